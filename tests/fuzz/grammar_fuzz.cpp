// grammar_fuzz.cpp — libFuzzer target: any bytes as a `.lsys` grammar or a cpfg model file, parsed, derived
// (at most kMaxSteps steps and kMaxModules modules, so one input stays milliseconds),
// interpreted and read by the turtle, as `sylva grow` does. Properties beyond "no crash,
// no sanitizer finding": every error formats to a message naming the file, and a grown
// skeleton passes validate_skeleton and reads back equal from its JSON (docs/spec/skeleton.md).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
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

// The grammar's name: a file in an empty folder of its own, so that a cpfg input's
// #include finds nothing but itself (docs/cpfg.md) whatever folder the fuzzer runs in.
const std::string& grammar_path() {
  static const std::string path = [] {
    char folder[] = "/tmp/sylva_grammar_fuzz_XXXXXX";
    if (!mkdtemp(folder)) fail("cannot make a folder", folder);
    return std::string(folder) + "/fuzz.lsys";
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string& path = grammar_path();
  sylva::Expected<sylva::lsys::Grammar> grammar = sylva::lsys::parse_grammar(text, path);
  if (!grammar) {
    sylva::fuzz::check_error("grammar_fuzz", grammar.error(), path);
    return 0;
  }
  sylva::lsys::DeriveOptions options;
  options.steps = std::min(grammar->steps, kMaxSteps);
  options.max_modules = kMaxModules;
  sylva::Expected<sylva::GrowResult> grown = sylva::grow(*grammar, options, path, {});
  if (!grown) {
    sylva::fuzz::check_error("grammar_fuzz", grown.error(), path);
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
