// vlab_object.cpp — vlab objects and cpfg view files (see vlab_object.h).
#include "lsystem/vlab_object.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/util/file_io.h"
#include "lsystem/source_text.h"

namespace sylva::lsys {

namespace {

using namespace detail;  // NOLINT: lsystem's own text helpers

// A whitespace-separated word of a line and its 1-based column.
struct Token {
  std::string text;
  uint32_t column;
};

std::vector<Token> tokens_of(std::string_view line) {
  std::vector<Token> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (is_space(line[i]) || line[i] == ',')) ++i;
    const size_t start = i;
    while (i < line.size() && !is_space(line[i]) && line[i] != ',') ++i;
    if (i > start) out.push_back({std::string(line.substr(start, i - start)), static_cast<uint32_t>(start + 1)});
  }
  return out;
}

// A located error in a text file we hold (the specifications or a view file).
Diagnostic error_in(const std::string& file, std::string_view line, uint32_t line_no, uint32_t column, std::string message) {
  Diagnostic d = diagnostic_at(file, {line_no, column}, std::move(message));
  set_source_line(d, line);
  return d;
}

// Blanks /* */ comments (view files take C comments) keeping lines; an unclosed one runs to the end.
std::string without_comments(std::string text) {
  for (size_t i = 0; i + 1 < text.size(); ++i) {
    if (text[i] != '/' || text[i + 1] != '*') continue;
    size_t end = text.find("*/", i + 2);
    end = end == std::string::npos ? text.size() : end + 2;
    for (size_t k = i; k < end; ++k)
      if (text[k] != '\n') text[k] = ' ';
    i = end - 1;
  }
  return text;
}

bool number(const std::string& text, double* value) {
  const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
  auto [ptr, ec] = std::from_chars(first, text.data() + text.size(), *value);
  return ec == std::errc() && ptr == text.data() + text.size() && std::isfinite(*value);
}

// How many arguments each cpfg option takes (CPFG manual 1.2.1, 1.2.2).
int option_arguments(const std::string& option) {
  static const std::pair<const char*, int> kOptions[] = {
      {"-a", 0},   {"-C", 1},   {"-d", 0},   {"-g", 0},    {"-homo", 0}, {"-rmode", 1}, {"-v", 0},  {"-V", 0},
      {"-w", 2},   {"-wnb", 0}, {"-wp", 2},  {"-wpr", 2},  {"-wr", 2},   {"-wt", 1},    {"-e", 1},  {"-gls", 1},
      {"-m", 1},   {"-M", 1},   {"-ps", 1},  {"-ray", 1},  {"-str", 1},  {"-strb", 1},  {"-vv", 1}};
  for (const auto& [name, count] : kOptions)
    if (option == name) return count;
  if (option.size() > 2 && option.compare(0, 2, "-m") == 0 &&
      std::all_of(option.begin() + 2, option.end(), [](char c) { return is_digit(c); }))
    return 1;  // -m1, -m2: colour maps for index ranges
  return -1;
}

}  // namespace

bool is_grammar_path(const std::string& path) {
  std::error_code ec;
  return path.ends_with(".lsys") || path.ends_with(".l") || std::filesystem::is_directory(path, ec);
}

Status apply_view_file(const std::string& path, Grammar& grammar) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  const std::string clean = without_comments(std::move(*text));
  TurtleDefaults& t = grammar.turtle;
  double line_width = 1;  // cpfg's defaults (manual 8.1.1): 1 pixel wide, no increment
  double width_increment = 0;
  bool world_units = false;
  std::optional<Diagnostic> failure;
  for_each_physical_line(clean, [&](uint32_t line_no, std::string_view line, bool) {
    if (failure) return;
    const size_t colon = line.find(':');
    if (colon == std::string_view::npos) return;  // not a command (a blank or stray line): cpfg skips it
    std::string name = lower_ascii(line.substr(0, colon));
    while (!name.empty() && is_space(name.back())) name.pop_back();
    while (!name.empty() && is_space(name.front())) name.erase(name.begin());
    const std::vector<Token> values = tokens_of(line.substr(colon + 1));
    const uint32_t value_column = static_cast<uint32_t>(colon + 2);
    auto fail_here = [&](uint32_t column, std::string message) {
      failure = error_in(path, line, line_no, column, std::move(message));
    };
    auto value = [&](size_t k, double* out) {
      if (k < values.size() && number(values[k].text, out)) return true;
      fail_here(k < values.size() ? values[k].column + value_column - 1 : value_column,
                "'" + name + ":' needs a number here");
      return false;
    };
    double v = 0;
    if (name == "angle increment") {
      if (value(0, &v)) t.angle_deg = v;
    } else if (name == "angle factor") {
      if (value(0, &v)) {
        if (v == 0) return fail_here(values[0].column + value_column - 1, "'angle factor:' must not be 0 (the angle is 360 / factor)");
        t.angle_deg = 360 / v;
      }
    } else if (name == "initial line width") {
      if (!value(0, &v)) return;
      if (v < 0) return fail_here(values[0].column + value_column - 1, "a line width must not be negative");
      line_width = v;
      if (values.size() > 1) {
        const std::string style = lower_ascii(values[1].text);
        if (style == "p" || style == "pixels") world_units = false;
        else if (style == "s" || style == "shaded") world_units = true;
        else return fail_here(values[1].column + value_column - 1, "expected 'p', 'pixels', 's' or 'shaded' as the line style");
      }
    } else if (name == "line width increment") {
      if (value(0, &v)) width_increment = v;
    } else if (name == "initial scale" || name == "scale multiplier") {
      if (!value(0, &v)) return;
      if (v == 0 || !std::isfinite(v) || std::abs(v) > 1e12)
        return fail_here(values[0].column + value_column - 1, "'" + name + ":' must be a non-zero number of at most 1e12");
      (name == "initial scale" ? t.initial_scale : t.scale_multiplier) = v;
    } else if (name == "line style") {
      if (values.empty()) return fail_here(value_column, "'line style:' needs pixel, polygon or cylinder");
      const std::string style = lower_ascii(values[0].text);
      if (style == "pixel") world_units = false;
      else if (style == "polygon" || style == "cylinder") world_units = true;
      else fail_here(values[0].column + value_column - 1, "expected pixel, polygon or cylinder as the line style");
    } else if (name == "initial color") {
      if (value(0, &v)) {
        if (v < 0 || v != std::floor(v)) return fail_here(values[0].column + value_column - 1, "a colour index is a whole number from 0");
        t.initial_color = static_cast<uint32_t>(v);
      }
    } else if (name == "color increment") {
      if (value(0, &v)) {
        if (v < 0 || v != std::floor(v)) return fail_here(values[0].column + value_column - 1, "a colour increment is a whole number from 0");
        t.color_increment = static_cast<uint32_t>(v);
      }
    } else if (name == "torque") {
      return fail_here(1, "a torque (a twist toward a vector, CPFG manual 8.1.8) is not supported yet (docs/cpfg.md)");
    } else if (name == "tropism") {
      // "T: x y z A: angle I: intensity E: elasticity S: step" (manual 8.1.8).
      if (t.view_tropisms.size() >= lsys::kMaxViewTropisms)
        return fail_here(1, "more than " + std::to_string(lsys::kMaxViewTropisms) + " tropisms");
      double vec[3] = {0, 0, 0}, intensity = 1, elasticity = 0, angle = 0, step = 0;
      bool has_vector = false;
      for (size_t k = 0; k < values.size(); ++k) {
        const std::string key = values[k].text;
        auto read = [&](double* out) { return value(k + 1, out) && (++k, true); };
        if (key == "T:") {
          has_vector = read(&vec[0]) && read(&vec[1]) && read(&vec[2]);
          if (!has_vector) return;
        } else if (key == "A:") {
          if (!read(&angle)) return;
        } else if (key == "I:") {
          if (!read(&intensity)) return;
        } else if (key == "E:") {
          if (!read(&elasticity)) return;
        } else if (key == "S:") {
          if (!read(&step)) return;
        } else {
          return fail_here(values[k].column + value_column - 1, "expected T:, A:, I:, E: or S: in the tropism");
        }
      }
      if (!has_vector) return fail_here(value_column, "a tropism needs its vector: 'tropism: T: x y z ...'");
      // As cpfg's read_movement (cpfg/movements.c): T normalised, times the intensity, the
      // factor I / |T| clamped to [-1, 1] — so an intensity above 1 bends no more than 1.
      const double length = std::sqrt(vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2]);
      if (!(length > 0) || !std::isfinite(length)) return fail_here(value_column, "a tropism's vector must not be 0");
      const double factor = std::clamp(intensity / length, -1.0, 1.0);
      lsys::ViewTropism tropism;
      for (int k = 0; k < 3; ++k) tropism.vector[k] = vec[k] * factor;
      tropism.angle_deg = angle;
      tropism.elasticity = elasticity;
      tropism.step = step;
      t.view_tropisms.push_back(tropism);
    }
    // Every other command only changes cpfg's window, its lights, textures or fonts: read
    // and ignored (docs/cpfg.md).
  });
  if (failure) return std::move(*failure);
  t.width_scale = world_units ? 0.5 : 0.05;  // a world-unit width is a diameter
  t.width = line_width * t.width_scale;
  t.width_increment = width_increment;
  return {};
}

Expected<Grammar> load_vlab_object(const std::string& folder, const ParseOptions& options) {
  namespace fs = std::filesystem;
  const std::string specifications = (fs::path(folder) / "specifications").string();
  Expected<std::string> text = read_text_file(specifications);
  if (!text)
    return file_diagnostic(folder, "not a vlab object: " + text.error().message + " (a vlab object is a folder with a "
                                   "'specifications' file naming its cpfg command)");
  std::optional<Diagnostic> failure;
  std::string model, view;
  uint32_t command_line = 0;
  std::string command_text;
  for_each_physical_line(*text, [&](uint32_t line_no, std::string_view line, bool) {
    if (failure || !model.empty()) return;
    const std::vector<Token> words = tokens_of(line);
    if (words.empty() || fs::path(words[0].text).filename() != "cpfg") return;
    command_line = line_no;
    command_text = std::string(line);
    std::vector<const Token*> files;
    for (size_t k = 1; k < words.size(); ++k) {
      const Token& w = words[k];
      if (w.text[0] != '-') {
        files.push_back(&w);
        continue;
      }
      const int count = option_arguments(w.text);
      if (count < 0) return void(failure = error_in(specifications, line, line_no, w.column, "unknown cpfg option '" + w.text + "'"));
      if (w.text == "-e")
        return void(failure = error_in(specifications, line, line_no, w.column,
                                       "an environmental program (cpfg -e) is not supported: sylva answers ?E queries "
                                       "itself, with a scene's environment (docs/cpfg.md)"));
      if (count > 0 && k + static_cast<size_t>(count) >= words.size())
        return void(failure = error_in(specifications, line, line_no, w.column, "cpfg option '" + w.text + "' needs " +
                                                                                    std::to_string(count) + " argument(s)"));
      k += static_cast<size_t>(count);
    }
    if (files.size() < 2)
      return void(failure = error_in(specifications, line, line_no, words[0].column,
                                     "the cpfg command needs the model and the view file: cpfg [options] model.l view.v"));
    model = (fs::path(folder) / files[0]->text).string();
    view = (fs::path(folder) / files[1]->text).string();
  });
  if (failure) return std::move(*failure);
  if (model.empty())
    return file_diagnostic(specifications, "no cpfg command: a vlab object of cpfg names it on a line "
                                           "'cpfg [options] model.l view.v' (is this object for another program?)");
  Expected<Grammar> g = load_grammar(model, options);
  if (!g) return g;
  if (Status s = apply_view_file(view, *g); !s) return std::move(s.error());
  return g;
}

}  // namespace sylva::lsys
