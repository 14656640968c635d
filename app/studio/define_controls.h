// define_controls.h — the parameter panel's view of a grammar's `#define` lines
// (docs/spec/grammar.md "Header directives"): where each define's value stands in the text, and
// the slider range a comment right after the value gives:
//     #define LIMBS 3 /* [1, 8, 1] */      min 1, max 8, step 1
//     #define ANGLE 22.5 /* [0, 90] */     min 0, max 90, continuous
// A define without such a comment gets a typed field. The values themselves come from
// the parsed grammar (a value may be an expression over other defines); this file only
// finds the text, so "write to text" can replace a value without touching anything else.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sylva::studio {

struct DefineLine {
  std::string name;
  uint32_t line = 0;             // 1-based
  size_t value_begin = 0;        // byte offsets of the value's text in the whole text
  size_t value_end = 0;
  std::string value_text;        // the value as written ("3", "2*R_TRUNK")
  std::optional<double> min, max, step;  // from "/* [min, max(, step)] */"
  bool has_range() const { return min && max && *min < *max; }
};

// Every `#define NAME VALUE` line of `text`, in order. A range comment that does not
// read as two or three numbers with min < max is ignored (the define gets a typed field).
std::vector<DefineLine> scan_defines(std::string_view text);

// `text` with the value of `line` (found by scan_defines on this very text) replaced by
// `value` in shortest round-trip form; the range comment and the rest stay.
std::string with_define_value(std::string_view text, const DefineLine& line, double value);

// The shortest decimal that reads back as exactly `value` ("0.1", "3", "1e-07").
std::string shortest(double value);

// The value a slider stands for at `value`: among the numbers within `resolution / 2` of it
// (a slider's resolution: its range over its width in pixels, or its step), the one with
// the fewest decimals, nearest to `value` — so that "Write to text" writes 6.14, not
// 6.1363638043403625, and a step of 0.1 gives 0.3, not 0.30000000000000004. `value` itself
// where resolution is not a positive finite number.
double slider_value(double value, double resolution);

// Parses a number typed in a field exactly (the whole text, no trailing junk); nullopt
// when it is not a finite number.
std::optional<double> parse_exact(std::string_view text);

}  // namespace sylva::studio
