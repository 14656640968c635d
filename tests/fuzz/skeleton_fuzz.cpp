// skeleton_fuzz.cpp — libFuzzer target: any bytes as a `.skel.json` skeleton
// (docs/spec/skeleton.md). Properties beyond "no crash, no sanitizer finding": an error names the
// file; a skeleton the reader accepts passes validate_skeleton, and writing it reads back
// equal (the format round-trips every double).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "core/geometry/skeleton.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) { sylva::fuzz::fail("skeleton_fuzz", what, detail); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sylva::Expected<sylva::Skeleton> skeleton = sylva::read_skeleton_json(text, "fuzz.skel.json");
  if (!skeleton) {
    sylva::fuzz::check_error("skeleton_fuzz", skeleton.error(), "fuzz.skel.json");
    return 0;
  }
  if (sylva::Status valid = sylva::validate_skeleton(*skeleton); !valid)
    fail("the reader accepted an invalid skeleton", valid.error().format());
  const std::string json = sylva::write_skeleton_json(*skeleton);
  sylva::Expected<sylva::Skeleton> back = sylva::read_skeleton_json(json, "fuzz.skel.json");
  if (!back) fail("a skeleton's JSON does not read back", back.error().format());
  if (!(*back == *skeleton)) fail("a skeleton's JSON reads back different", json);
  return 0;
}
