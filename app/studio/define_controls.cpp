// define_controls.cpp — see define_controls.h.
#include "app/studio/define_controls.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/grow/grow.h"

namespace sylva::studio {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t'; }
bool is_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}

// Reads "[a, b]" or "[a, b, s]" (spaces allowed) from the inside of a comment.
void read_range(std::string_view body, DefineLine& d) {
  size_t open = body.find('['), close = body.find(']');
  if (open == std::string_view::npos || close == std::string_view::npos || close < open) return;
  for (size_t k = 0; k < open; ++k)
    if (!is_space(body[k])) return;
  std::vector<double> numbers;
  std::string_view inner = body.substr(open + 1, close - open - 1);
  size_t start = 0;
  while (start <= inner.size()) {
    size_t comma = inner.find(',', start);
    std::string_view part = inner.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!part.empty() && is_space(part.front())) part.remove_prefix(1);
    while (!part.empty() && is_space(part.back())) part.remove_suffix(1);
    auto v = parse_exact(part);
    if (!v) return;
    numbers.push_back(*v);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (numbers.size() < 2 || numbers.size() > 3 || !(numbers[0] < numbers[1])) return;
  if (numbers.size() == 3 && !(numbers[2] > 0)) return;
  d.min = numbers[0];
  d.max = numbers[1];
  if (numbers.size() == 3) d.step = numbers[2];
}

}  // namespace

std::optional<double> parse_exact(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  if (text.empty()) return std::nullopt;
  if (text.front() == '+') text.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string shortest(double value) {
  std::string out;
  lsys::append_shortest_double(out, value);
  return out;
}

double slider_value(double value, double resolution) {
  if (!std::isfinite(value) || !(resolution > 0) || !std::isfinite(resolution)) return value;
  const double tolerance = resolution / 2;
  // Decimal places from the coarsest that can matter to the finest a double holds.
  const int coarsest = -static_cast<int>(std::floor(std::log10(std::max(std::abs(value), tolerance)))) - 1;
  for (int places = std::max(coarsest, -15); places <= 17; ++places) {
    char text[64];
    const double scale = std::pow(10.0, places);
    // Rounded as text (exact decimal), read back: the double the text stands for.
    std::snprintf(text, sizeof text, "%.*f", std::max(places, 0), std::round(value * scale) / scale);
    const double candidate = std::strtod(text, nullptr);
    if (std::abs(candidate - value) <= tolerance) return candidate;
  }
  return value;
}

std::vector<DefineLine> scan_defines(std::string_view text) {
  std::vector<DefineLine> out;
  size_t pos = 0;
  uint32_t line = 1;
  while (pos <= text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view l = text.substr(pos, eol - pos);
    size_t i = 0;
    while (i < l.size() && is_space(l[i])) ++i;
    if (l.substr(i, 7) == "#define" && i + 7 < l.size() && is_space(l[i + 7])) {
      i += 7;
      while (i < l.size() && is_space(l[i])) ++i;
      size_t name_begin = i;
      while (i < l.size() && is_name_char(l[i])) ++i;
      DefineLine d;
      d.name = std::string(l.substr(name_begin, i - name_begin));
      d.line = line;
      // A function-like macro of a cpfg file (docs/cpfg.md) has no value to set.
      const bool function_like = i < l.size() && l[i] == '(';
      while (i < l.size() && is_space(l[i])) ++i;
      size_t value_begin = i;
      size_t comment = l.find("/*", i);
      size_t value_end = comment == std::string_view::npos ? l.size() : comment;
      // A cpfg file's `//` comment ends the value too (in sylva's format a value never holds '//').
      if (size_t slashes = l.substr(0, value_end).find("//", i); slashes != std::string_view::npos) value_end = slashes;
      if (value_end > value_begin && l[value_end - 1] == '\r') --value_end;
      while (value_end > value_begin && is_space(l[value_end - 1])) --value_end;
      if (!d.name.empty() && !function_like && value_end > value_begin) {
        d.value_begin = pos + value_begin;
        d.value_end = pos + value_end;
        d.value_text = std::string(l.substr(value_begin, value_end - value_begin));
        if (comment != std::string_view::npos) {
          size_t close = l.find("*/", comment + 2);
          if (close != std::string_view::npos) read_range(l.substr(comment + 2, close - comment - 2), d);
        }
        out.push_back(std::move(d));
      }
    }
    if (eol == text.size()) break;
    pos = eol + 1;
    ++line;
  }
  return out;
}

std::string with_define_value(std::string_view text, const DefineLine& line, double value) {
  std::string out(text.substr(0, line.value_begin));
  out += shortest(value);
  out += text.substr(line.value_end);
  return out;
}

}  // namespace sylva::studio
