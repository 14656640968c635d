// gltf_format.h — the numbers of the glTF 2.0 binary container and of sylva's "compact"
// extras that the writer (gltf_writer.cpp) and the reader (gltf_reader.cpp) must agree on.
// Internal to core/io/.
#pragma once

#include <cstdint>
#include <limits>

namespace sylva::gltf_format {

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"
// A root chain's "parent" (chain and joint) in the "compact" extras' parent arrays.
constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();

}  // namespace sylva::gltf_format
