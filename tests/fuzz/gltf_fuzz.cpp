// gltf_fuzz.cpp — libFuzzer target: any bytes as a `.gltf` or `.glb` file read back into
// sylva skeletons (parse_gltf_skeletons: the `sylva render plant.glb` import path; GLB
// header and chunks, JSON, node extras "full" or "compact" — the latter's bufferViews in
// the BIN chunk or a base64 data URI, seeded by corpus/gltf/*compact*). Properties beyond
// "no crash, no sanitizer finding": an error names the file, and every imported plant's
// skeleton is valid.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/io/gltf.h"
#include "core/geometry/skeleton.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) { sylva::fuzz::fail("gltf_fuzz", what, detail); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sylva::Expected<std::vector<sylva::GltfPlant>> plants = sylva::parse_gltf_skeletons(bytes, "fuzz.glb");
  if (!plants) {
    sylva::fuzz::check_error("gltf_fuzz", plants.error(), "fuzz.glb");
    return 0;
  }
  for (const sylva::GltfPlant& p : *plants)
    if (sylva::Status valid = sylva::validate_skeleton(p.skeleton); !valid)
      fail("an imported skeleton is invalid", valid.error().format());
  return 0;
}
