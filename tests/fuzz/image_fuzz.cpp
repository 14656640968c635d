// image_fuzz.cpp — libFuzzer target: any bytes as a texture or height-map image, through
// the two ways sylva loads one (OpenImageIO reads files by path only, so each input is
// written to one file under /dev/shm first): check_image_opens, the scene reader's
// header check (docs/limits.md: size limits before anything is allocated), then, for an
// image that passes it, read_height_map. Properties beyond "no crash, no sanitizer
// finding": a height map read is non-empty, its size within the limits, and its values
// finite (normal_map.h).
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/io/normal_map.h"
#include "core/util/image_io.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) { sylva::fuzz::fail("image_fuzz", what, detail); }

// The extension picks OpenImageIO's first reader to try; it then tries every other one.
const std::string kPath = "/dev/shm/sylva_image_fuzz_" + std::to_string(getpid()) + ".png";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::FILE* file = std::fopen(kPath.c_str(), "wb");
  if (!file) fail("cannot write the input file", kPath);
  if (size > 0 && std::fwrite(data, 1, size, file) != size) fail("cannot write the input file", kPath);
  std::fclose(file);
  if (sylva::Status opens = sylva::check_image_opens(kPath); !opens) return 0;
  sylva::Expected<sylva::HeightMap> map = sylva::read_height_map(kPath);
  if (!map) return 0;
  if (map->width == 0 || map->height == 0 || map->values.size() != size_t{map->width} * map->height)
    fail("a height map of the wrong size", std::to_string(map->width) + " x " + std::to_string(map->height));
  for (float v : map->values)
    if (!std::isfinite(v)) fail("a height map with a non-finite value", std::to_string(v));
  return 0;
}
