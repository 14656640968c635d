// grammar_fuzz.cpp — libFuzzer target: any bytes as a `.lsys` grammar, parsed, derived
// (at most kMaxSteps steps and kMaxModules modules, so one input stays milliseconds),
// interpreted and read by the turtle, as `sylva grow` does. Properties beyond "no crash,
// no sanitizer finding": every error formats to a message naming the file, and a grown
// skeleton passes validate_skeleton and reads back equal from its JSON (docs/spec/skeleton.md).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "core/geometry/skeleton.h"
#include "core/grow/grow.h"
#include "core/grow/turtle.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

constexpr int64_t kMaxSteps = 5;
constexpr uint64_t kMaxModules = 4096;

[[noreturn]] void fail(const char* what, const std::string& detail) { sylva::fuzz::fail("grammar_fuzz", what, detail); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sylva::Expected<sylva::lsys::Grammar> grammar = sylva::lsys::parse_grammar(text, "fuzz.lsys");
  if (!grammar) {
    sylva::fuzz::check_error("grammar_fuzz", grammar.error(), "fuzz.lsys");
    return 0;
  }
  sylva::lsys::DeriveOptions options;
  options.steps = std::min(grammar->steps, kMaxSteps);
  options.max_modules = kMaxModules;
  sylva::Expected<sylva::GrowResult> grown = sylva::grow(*grammar, options, "fuzz.lsys", {});
  if (!grown) {
    sylva::fuzz::check_error("grammar_fuzz", grown.error(), "fuzz.lsys");
    return 0;
  }
  if (sylva::Status valid = sylva::validate_skeleton(grown->skeleton); !valid)
    fail("grow made an invalid skeleton", valid.error().format());
  const std::string json = sylva::write_skeleton_json(grown->skeleton);
  sylva::Expected<sylva::Skeleton> back = sylva::read_skeleton_json(json, "fuzz.skel.json");
  if (!back) fail("a grown skeleton's JSON does not read back", back.error().format());
  if (!(*back == grown->skeleton)) fail("a grown skeleton's JSON reads back different", json);
  return 0;
}
