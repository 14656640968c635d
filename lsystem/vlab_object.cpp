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
#include "lsystem/spline_function.h"

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

// A view, environment or specification file's command line "name: values": the name in lower
// case without the blanks around it, and where its colon is; nullopt for a line without one
// (blank or stray: cpfg skips it).
std::optional<size_t> command_of(std::string_view line, std::string* name) {
  const size_t colon = line.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  *name = lower_ascii(line.substr(0, colon));
  while (!name->empty() && is_space(name->back())) name->pop_back();
  while (!name->empty() && is_space(name->front())) name->erase(name->begin());
  return colon;
}

// The view file's user-defined functions (CPFG manual 8.1.6), in order: `function: file [n]`
// and `function set: file` (a set replaces the functions before it, as cpfg's reader does, and
// its names become macros NAME = id for the model, as cpfg's -D). Files are in the object's
// folder. Read before the model is preprocessed, since the model may use those names.
Status read_view_functions(const std::string& view, const std::string& folder, ParseOptions& options) {
  namespace fs = std::filesystem;
  Expected<std::string> text = read_text_file(view);
  if (!text) return std::move(text.error());
  const std::string clean = without_comments(std::move(*text));
  bool from_set = false;
  std::optional<Diagnostic> failure;
  for_each_physical_line(clean, [&](uint32_t line_no, std::string_view line, bool) {
    if (failure) return;
    std::string name;
    const std::optional<size_t> found = command_of(line, &name);
    if (!found) return;  // not a command: cpfg skips it
    const size_t colon = *found;
    if (name != "function" && name != "function set" && name != "curve") return;
    const std::vector<Token> values = tokens_of(line.substr(colon + 1));
    const uint32_t base = static_cast<uint32_t>(colon + 1);
    if (values.empty()) return void(failure = error_in(view, line, line_no, base + 1, "'" + name + ":' needs a file name"));
    const std::string file = (fs::path(folder) / values[0].text).string();
    auto fail_file = [&](Diagnostic inner) {
      Diagnostic d = error_in(view, line, line_no, base + values[0].column,
                              std::string("cannot read the ") + (name == "curve" ? "curve" : "function") + " file '" +
                                  values[0].text + "'");
      d.notes.push_back(std::move(inner));
      failure = std::move(d);
    };
    // The line's optional sample count (its second word): `fallback` without one, else a whole
    // number from `low` to `high`; false after an error at it.
    auto samples_of = [&](int fallback, int low, int high, int* out) {
      double v = fallback;
      if (values.size() >= 2 && (!number(values[1].text, &v) || v != std::floor(v) || v < low || v > high)) {
        failure = error_in(view, line, line_no, base + values[1].column,
                           "the number of samples is a whole number from " + std::to_string(low) + " to " +
                               std::to_string(high));
        return false;
      }
      *out = static_cast<int>(v);
      return true;
    };
    int samples = 0;
    if (name == "curve") {
      // "curve: file [samples]" (CPFG manual 8.1.5): curveX(id, t) ... with ids 1, 2, ... in
      // order; cpfg measures it with 100 samples without the number (interpret.c).
      if (!samples_of(100, 2, kMaxCurveSamples, &samples)) return;
      auto c = read_cpfg_curve(file, samples);
      if (!c) return fail_file(std::move(c.error()));
      options.curves.push_back(std::move(*c));
      return;
    }
    if (name == "function set") {
      auto set = read_function_set(file);
      if (!set) return fail_file(std::move(set.error()));
      options.functions = std::move(*set);
      from_set = true;
      return;
    }
    if (!samples_of(0, 0, kMaxFunctionSamples, &samples)) return;
    auto f = read_function_file(file, samples);
    if (!f) return fail_file(std::move(f.error()));
    if (f->name == file) f->name = fs::path(values[0].text).stem().string();
    options.functions.push_back(std::move(*f));
  });
  if (failure) return std::move(*failure);
  if (from_set)
    for (size_t i = 0; i < options.functions.size(); ++i) {
      const std::string& n = options.functions[i].name;
      if (!n.empty() && is_ident_start(n[0]) && std::all_of(n.begin(), n.end(), [](char c) { return is_ident_char(c); }))
        options.predefined_macros.emplace_back(n, std::to_string(i + 1));
    }
  return {};
}

// The environment file `path` of `cpfg -e` (vlab's environment manual: `executable: program
// args`, `communication type:`, `turtle position:` ...). For a program sylva has built in
// (honda81, chiba) its specification file, the executable's last word, is read too. Another
// program: `*program` is its name and the error is where the file names it; an unreadable
// file leaves `*program` empty.
Expected<Grammar::Environment> read_environment(const std::string& path, const std::string& folder,
                                                std::string* program) {
  namespace fs = std::filesystem;
  program->clear();
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  std::string spec, communication = "memory", formats_line;
  uint32_t executable_line = 0, formats_line_no = 0;
  std::string executable_text;
  for_each_physical_line(*text, [&](uint32_t line_no, std::string_view line, bool) {
    std::string name;
    const std::optional<size_t> found = command_of(line, &name);
    if (!found) return;  // not a command: cpfg skips it
    const size_t colon = *found;
    const std::vector<Token> values = tokens_of(line.substr(colon + 1));
    if (name == "executable" && !values.empty()) {
      *program = fs::path(values[0].text).filename().string();
      executable_line = line_no;
      executable_text = std::string(line);
      // program [-e environment_file] specification_file: the last word is its spec file.
      if (values.size() >= 2) spec = values.back().text;
    } else if (name == "communication type" && !values.empty()) {
      communication = lower_ascii(values[0].text);
    } else if (name == "turtle position") {
      formats_line = std::string(line.substr(colon + 1));
      formats_line_no = line_no;
    }
  });
  if (program->empty()) return file_diagnostic(path, "no 'executable:' line naming the environmental program");
  if (*program != "honda81" && *program != "chiba")
    return error_in(path, executable_text, executable_line, 1, "the environmental program is '" + *program + "'");
  Grammar::Environment env;
  env.program = *program;
  // "turtle position:P:%.4f %.4f %.0f": the position is sent, written with these conversions
  // when the program reads files or pipes.
  if (formats_line_no == 0)
    return file_diagnostic(path, *program + " needs the turtle's position: a line 'turtle position:P:%g %g %g'");
  size_t p = formats_line.find("P:");  // the field's tag, which older files leave out
  p = p == std::string::npos ? 0 : p + 2;
  if (communication == "files" || communication == "pipes") {
    for (const Token& t : tokens_of(std::string_view(formats_line).substr(p))) {
      const FormatCheck check = check_format(t.text);
      if (!check.error.empty() || check.values != 1)
        return error_in(path, formats_line, formats_line_no, static_cast<uint32_t>(p + t.column + 16),
                        "expected one number's conversion for each coordinate ('%.4f')");
      env.position_formats.push_back(t.text);
    }
    if (env.position_formats.size() != 3)
      return error_in(path, formats_line, formats_line_no, 1, "expected three conversions, x y z ('%.4f %.4f %.4f')");
  }
  if (spec.empty())
    return error_in(path, executable_text, executable_line, 1,
                    *program + " needs its specification file: 'executable: " + *program + " file.spec'");
  const std::string spec_path = (fs::path(folder) / spec).string();
  Expected<std::string> spec_text = read_text_file(spec_path);
  if (!spec_text) return std::move(spec_text.error());
  std::optional<Diagnostic> failure;
  Grammar::Chiba& chiba = env.chiba;
  for_each_physical_line(*spec_text, [&](uint32_t line_no, std::string_view line, bool) {
    if (failure) return;
    std::string name;
    const std::optional<size_t> found = command_of(line, &name);
    if (!found) return;  // not a command: cpfg skips it
    const size_t colon = *found;
    const std::vector<Token> values = tokens_of(line.substr(colon + 1));
    if (values.empty()) return;
    auto fail_at = [&](size_t k, const std::string& message) {
      failure = error_in(spec_path, line, line_no, static_cast<uint32_t>(colon + 1 + values[k].column), message);
    };
    // The k-th value as a number in [low, high]; else an error there saying `what`.
    auto read = [&](size_t k, double low, double high, double* out, const std::string& what) {
      double v = 0;
      if (k >= values.size()) {
        failure = error_in(spec_path, line, line_no, static_cast<uint32_t>(line.size() + 1), what);
        return false;
      }
      if (!number(values[k].text, &v) || v < low || v > high) {
        fail_at(k, what);
        return false;
      }
      *out = v;
      return true;
    };
    const std::string word = lower_ascii(values[0].text);
    if (*program == "honda81") {
      if (name == "radius") read(0, 0, 1e12, &env.honda81.radius, "honda81's radius is a number, not negative");
      else if (name == "3d case") env.honda81.three_d = word == "on";
      // verbose: and anything else honda81 skips with a message: read and ignored.
      return;
    }
    // chiba's keywords (ENVIRO/chiba/chiba.c); `grid size:` sizes its voxel grid, which
    // sylva sizes itself (the answers do not depend on it), `verbose:` its messages.
    if (name == "lower to upper ratio") {
      read(0, 0, 1e6, &chiba.lower_to_upper, "the lower to upper ratio is a number, not negative");
    } else if (name == "transmittance") {
      read(0, 0, 1, &chiba.transmittance, "the transmittance is a number from 0 to 1");
    } else if (name == "number of samples") {
      read(0, 1, 1e9, &chiba.samples, "the number of samples is a number from 1");
    } else if (name == "radius") {
      read(0, 0, 1e12, &chiba.radius, "chiba's radius is a number, not negative");
    } else if (name == "beam radius") {
      read(0, 0, 1e6, &chiba.beam_radius, "the beam radius is a number, not negative");
    } else if (name == "estimate intersection area") {
      chiba.estimate_area = word == "on";
    } else if (name == "use cie formula") {
      chiba.cie_sky = word == "yes";
    } else if (name == "source direction") {
      if (chiba.sources.size() >= 100) return fail_at(0, "chiba takes at most 100 light sources");
      Grammar::Chiba::Source src;
      for (size_t k = 0; k < 3; ++k)
        if (!read(k, -1e12, 1e12, &src.direction[k], "a source direction is 'x y z intensity', numbers")) return;
      if (src.direction[0] == 0 && src.direction[1] == 0 && src.direction[2] == 0)
        return fail_at(0, "a source's direction must not be zero");
      if (values.size() > 3 && !read(3, 0, 1e12, &src.intensity, "a source's intensity is a number, not negative")) return;
      chiba.sources.push_back(src);
    }
  });
  if (failure) return std::move(*failure);
  if (*program == "chiba") {
    double total = 0;
    for (const auto& src : chiba.sources) total += src.intensity;
    if (!chiba.sources.empty() && !(total > 0))
      return file_diagnostic(spec_path, "chiba's light sources have no intensity (they sum to 0)");
    if (chiba.estimate_area) chiba.beam_radius = 1;  // as chiba sets it
  }
  return env;
}

// cpfg's colour map (`-m`; irisGL.c's load_in_colormaps): 256 RGB byte triples, one for
// each colour index.
Expected<std::vector<Grammar::Colour>> read_colour_map(const std::string& path) {
  Expected<std::string> bytes = read_text_file(path, 4096);
  if (!bytes) return std::move(bytes.error());
  if (bytes->size() != 768)
    return file_diagnostic(path, "a colour map holds 256 RGB triples, 768 bytes; this file has " +
                                     std::to_string(bytes->size()));
  std::vector<Grammar::Colour> out(256);
  for (uint32_t i = 0; i < 256; ++i) {
    out[i].index = i;
    for (int c = 0; c < 3; ++c) out[i].srgb[c] = static_cast<unsigned char>((*bytes)[3 * i + c]) / 255.0;
  }
  return out;
}

// cpfg's material file (`-M`, medit's; irisGL.c's load_in_materials): records of 15 bytes,
// the colour index, then transparency, ambient RGB, diffuse RGB, emissive RGB, specular RGB
// and shininess. sylva takes the diffuse colour and the specular's brightest channel as its
// lobe's weight.
Expected<std::vector<Grammar::Colour>> read_material_file(const std::string& path) {
  Expected<std::string> bytes = read_text_file(path, 256 * 15 * 16);
  if (!bytes) return std::move(bytes.error());
  if (bytes->empty() || bytes->size() % 15 != 0)
    return file_diagnostic(path, "a material file holds records of 15 bytes (medit's); this file has " +
                                     std::to_string(bytes->size()) + " bytes");
  std::vector<Grammar::Colour> out;
  for (size_t r = 0; r + 15 <= bytes->size(); r += 15) {
    auto byte = [&](size_t k) { return static_cast<unsigned char>((*bytes)[r + k]); };
    Grammar::Colour c;
    c.index = byte(0);
    for (int k = 0; k < 3; ++k) c.srgb[k] = byte(5 + k) / 255.0;
    c.specular = std::max({byte(11), byte(12), byte(13)}) / 255.0;
    // A later record of the same index replaces the earlier, as cpfg's table does.
    auto same = std::find_if(out.begin(), out.end(), [&](const Grammar::Colour& o) { return o.index == c.index; });
    if (same != out.end()) *same = c;
    else out.push_back(c);
  }
  return out;
}

// A movement's words with each "K:value" split into "K:" and "value" (cpfg's reader splits
// them at ':', cpfg/movements.c: `tropism: T: 0 1 0 A:90`).
std::vector<Token> split_keys(const std::vector<Token>& words) {
  std::vector<Token> out;
  for (const Token& w : words) {
    if (w.text.size() > 2 && is_ident_start(w.text[0]) && w.text[1] == ':') {
      out.push_back({w.text.substr(0, 2), w.column});
      out.push_back({w.text.substr(2), w.column + 2});
    } else {
      out.push_back(w);
    }
  }
  return out;
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
    std::string name;
    const std::optional<size_t> found = command_of(line, &name);
    if (!found) return;  // not a command: cpfg skips it
    const size_t colon = *found;
    std::vector<Token> values = tokens_of(line.substr(colon + 1));
    const uint32_t value_column = static_cast<uint32_t>(colon + 2);
    auto fail_here = [&](uint32_t column, std::string message) {
      failure = error_in(path, line, line_no, column, std::move(message));
    };
    // A file the view file names (beside it) and the error where one cannot be read: at its
    // name, the file's own error as a note.
    auto beside = [&](const Token& name) { return (std::filesystem::path(path).parent_path() / name.text).string(); };
    auto fail_file = [&](const Token& name, const char* what, Diagnostic inner) {
      fail_here(name.column + value_column - 1, std::string("cannot read the ") + what + " file '" + name.text + "'");
      failure->notes.push_back(std::move(inner));
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
      // cpfg's reader (interpret.c) makes the style polygon, world units, and then reads the
      // next word's first letter: `p...` (pixels, pnts) is pixels, `s...` (shaded) cylinders,
      // anything else or nothing stays polygon. (The manual's table says pixels without a
      // word; cpfg's source draws world units, and so does sylva: docs/cpfg.md.)
      world_units = values.size() < 2 || lower_ascii(values[1].text)[0] != 'p';
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
      // cpfg's names or their numbers 1 to 3; any other word keeps the style as it was,
      // as cpfg does ("Invalid line style ... Default used!", interpret.c).
      if (style == "pixel" || style == "1") world_units = false;
      else if (style == "polygon" || style == "cylinder" || style == "2" || style == "3") world_units = true;
    } else if (name == "initial color" || name == "color increment") {
      // "initial color: front [back]" (CPFG manual 8.1.1): a second number turns cpfg's
      // double-sided surfaces on, the back side in its own colour (interpret.c);
      // "color increment: front [back]": the steps of ; , and of @; @,.
      const bool initial = name == "initial color";
      for (size_t k = 0; k < 2 && k < values.size(); ++k) {
        if (k == 1 && !number(values[1].text, &v)) break;  // not a number: one colour, as cpfg's fscanf
        if (!value(k, &v)) return;
        if (v < 0 || v != std::floor(v) || v > 4294967295.0)
          return fail_here(values[k].column + value_column - 1,
                           initial ? "a colour index is a whole number from 0" : "a colour increment is a whole number from 0");
        (initial ? (k ? t.initial_back_color : t.initial_color) : (k ? t.color_increment_back : t.color_increment)) =
            static_cast<uint32_t>(v);
        if (initial && k == 1) t.double_sided = true;
      }
    } else if (name == "contour") {
      // "contour: id file.con" (CPFG manual 8.1.5): @#(id) selects it.
      double id = 0;
      if (values.size() < 2 || !number(values[0].text, &id) || id != std::floor(id) || id < 1 || id > 1e6)
        return fail_here(value_column, "a contour needs 'contour: id file.con', the id a whole number from 1");
      auto contour = read_cpfg_contour(beside(values[1]), static_cast<int>(id));
      if (!contour) return fail_file(values[1], "contour", std::move(contour.error()));
      grammar.contours.push_back(std::move(*contour));
    } else if (name == "interpretation past %") {
      // On unless the word is "off" (interpret.c reads its first three letters).
      if (!values.empty()) t.interpret_past_cut = lower_ascii(values[0].text).rfind("off", 0) != 0;
    } else if (name == "contour sides" || name == "polygonization level") {
      // cpfg's points around a contour: n, or 2^(n + 1) for the level (interpret.c), at least 3.
      if (!value(0, &v)) return;
      const double sides = name == "contour sides" ? v : std::round(std::pow(2.0, std::min(v, 20.0) + 1));
      if (!(sides >= 1) || sides != std::floor(sides) || sides > lsys::kMaxContourSides)
        return fail_here(values[0].column + value_column - 1,
                         "the sides around a contour are a whole number up to " + std::to_string(lsys::kMaxContourSides));
      t.contour_sides = std::max(3, static_cast<int>(sides));
    } else if (name == "surface" || name == "tsurface") {
      // "surface: id file size [s t [texture]]" (CPFG manual 8.1.5): the id is one character,
      // a size not above 0 is 1 (as cpfg's reader), s and t the cells a patch is cut into.
      // "tsurface: id file.ray size" (8.1.5, 8.4): triangles, the size mandatory. Both are
      // drawn by ~id, so an id names one of them.
      const bool triangles = name == "tsurface";
      if (values.size() < 3)
        return fail_here(value_column, triangles ? "a tsurface needs 'tsurface: id file.ray size'"
                                                 : "a surface needs 'surface: id file.s size [s t]'");
      if (values[0].text.size() != 1)
        return fail_here(values[0].column + value_column - 1, "a " + name + "'s id is one character ('~" + values[0].text.substr(0, 1) + "' draws it)");
      for (const lsys::CpfgSurface& other : grammar.surfaces)
        if (other.id == values[0].text[0])
          return fail_here(values[0].column + value_column - 1,
                           "a second surface with the id '" + values[0].text + "' (~" + values[0].text + " draws one)");
      double size = 0, cells[2] = {0, 0};
      if (!number(values[2].text, &size)) return fail_here(values[2].column + value_column - 1, "a " + name + "'s size is a number");
      if (!(size > 0)) size = 1;
      if (triangles) {
        auto surface = read_cpfg_tsurface(beside(values[1]), values[0].text[0], size);
        if (!surface) return fail_file(values[1], "tsurface", std::move(surface.error()));
        grammar.surfaces.push_back(std::move(*surface));
        return;
      }
      for (size_t k = 0; k < 2 && 3 + k < values.size(); ++k)
        if (!number(values[3 + k].text, &cells[k]) || cells[k] != std::floor(cells[k]) || cells[k] < 0 || cells[k] > 1e6)
          return fail_here(values[3 + k].column + value_column - 1, "a surface's cells across and along are whole numbers");
      auto surface = read_cpfg_surface(beside(values[1]), values[0].text[0], size, static_cast<int>(cells[0]),
                                       static_cast<int>(cells[1]));
      if (!surface) return fail_file(values[1], "surface", std::move(surface.error()));
      grammar.surfaces.push_back(std::move(*surface));
    } else if (name == "tropism" || name == "torque") {
      // "T: x y z A: angle I: intensity E: elasticity S: step" (manual 8.1.8).
      if (t.view_tropisms.size() >= lsys::kMaxViewTropisms)
        return fail_here(1, "more than " + std::to_string(lsys::kMaxViewTropisms) + " tropisms and torques");
      double vec[3] = {0, 0, 0}, intensity = 1, elasticity = 0, angle = 0, step = 0;
      bool has_vector = false;
      values = split_keys(values);
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
      tropism.angle_deg = name == "torque" ? 0 : angle;  // a torque ignores A: (manual 8.1.8)
      tropism.elasticity = elasticity;
      tropism.step = step;
      tropism.torque = name == "torque";
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

namespace {

// load_vlab_object, and parse_vlab_object with the model's text given (`model_text`), or
// `*model_file` only: the model file's path, nothing parsed.
Expected<Grammar> read_vlab_object(const std::string& folder, const ParseOptions& options,
                                   const std::string* model_text, std::string* model_file) {
  namespace fs = std::filesystem;
  const std::string specifications = (fs::path(folder) / "specifications").string();
  Expected<std::string> text = read_text_file(specifications);
  if (!text)
    return file_diagnostic(folder, "not a vlab object: " + text.error().message + " (a vlab object is a folder with a "
                                   "'specifications' file naming its cpfg command)");
  std::optional<Diagnostic> failure;
  std::string model, view;
  struct EnvironmentOption {
    std::string file;
    uint32_t line = 0, column = 0;
    std::string text;
  };
  std::optional<EnvironmentOption> environment;  // cpfg -e file.e
  std::optional<EnvironmentOption> colour_file, map_file;  // cpfg -M file.mat, -m file.map
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
      if (count > 0 && k + static_cast<size_t>(count) >= words.size())
        return void(failure = error_in(specifications, line, line_no, w.column, "cpfg option '" + w.text + "' needs " +
                                                                                    std::to_string(count) + " argument(s)"));
      if (w.text == "-e") environment = {words[k + 1].text, line_no, w.column, std::string(line)};
      // The colours: a material file, else the first colour map (-m or -m1; -m2 ... colour
      // indices from 256, which sylva's colour steps never reach, are read by nobody).
      if (w.text == "-M") colour_file = {words[k + 1].text, line_no, w.column, std::string(line)};
      if ((w.text == "-m" || w.text == "-m1") && !map_file) map_file = {words[k + 1].text, line_no, w.column, std::string(line)};
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
  if (model_file) {
    *model_file = model;
    if (!model_text) return Grammar{};
  }
  ParseOptions with_functions = options;
  if (Status s = read_view_functions(view, folder, with_functions); !s) return std::move(s.error());
  std::optional<Grammar::Environment> field;
  if (environment) {
    // cpfg -e: vlab's honda81 and chiba are built in; any other program is not (docs/cpfg.md).
    std::string program;
    auto read = read_environment((fs::path(folder) / environment->file).string(), folder, &program);
    if (!read && (program == "honda81" || program == "chiba")) return std::move(read.error());
    if (!read && program.empty()) {
      Diagnostic d = error_in(specifications, environment->text, environment->line, environment->column,
                              "cannot read the environment file '" + environment->file + "' (cpfg -e)");
      d.notes.push_back(std::move(read.error()));
      return d;
    }
    if (!read) {
      Diagnostic d = error_in(specifications, environment->text, environment->line, environment->column,
                              "the environmental program '" + program + "' (cpfg -e " + environment->file +
                                  ") is not supported: sylva answers ?E with its own light (docs/light.md), or "
                                  "with vlab's honda81 or chiba, which it has built in (docs/cpfg.md)");
      d.notes.push_back(std::move(read.error()));
      return d;
    }
    field = std::move(*read);
  }
  Expected<Grammar> g = model_text ? parse_grammar(*model_text, model, with_functions) : load_grammar(model, with_functions);
  if (!g) return g;
  g->environment = std::move(field);
  if (Status s = apply_view_file(view, *g); !s) return std::move(s.error());
  if (const auto& file = colour_file ? colour_file : map_file;
      file && fs::exists(fs::path(folder) / file->file)) {  // none there: cpfg's defaults, as cpfg goes on
    const std::string path = (fs::path(folder) / file->file).string();
    auto colours = colour_file ? read_material_file(path) : read_colour_map(path);
    if (!colours) {
      Diagnostic d = error_in(specifications, file->text, file->line, file->column,
                              std::string("cannot read the ") + (colour_file ? "material file '" : "colour map '") +
                                  file->file + "'");
      d.notes.push_back(std::move(colours.error()));
      return d;
    }
    g->colours = std::move(*colours);
  }
  // cpfg gives a back side its own colour with a material file only (my_color: GL_BACK's
  // material); with a colour map both sides take the front's (docs/cpfg.md).
  if (!colour_file) g->turtle.double_sided = false;
  return g;
}

}  // namespace

Expected<Grammar> load_vlab_object(const std::string& folder, const ParseOptions& options) {
  return read_vlab_object(folder, options, nullptr, nullptr);
}

Expected<std::string> vlab_model_file(const std::string& folder) {
  std::string file;
  if (auto read = read_vlab_object(folder, {}, nullptr, &file); !read) return std::move(read.error());
  return file;
}

Expected<Grammar> parse_vlab_object(const std::string& folder, const std::string& model_text,
                                    const ParseOptions& options) {
  std::string file;
  return read_vlab_object(folder, options, &model_text, &file);
}

std::vector<PanelSlider> read_panel_sliders(std::string_view text) {
  std::vector<PanelSlider> out;
  // Items are blocks of "key: value" lines, each starting with "type:".
  std::string type, name, minmax, value, message;
  auto finish = [&] {
    if (lower_ascii(type) == "slider") {
      // message: "d NAME %d scale" — the parameter editor defines NAME as the value / scale.
      const std::vector<Token> m = tokens_of(message);
      const std::vector<Token> r = tokens_of(minmax);
      double lo = 0, hi = 0, scale = 1, v = 0;
      if (m.size() == 4 && m[0].text == "d" && m[2].text == "%d" && number(m[3].text, &scale) && scale != 0 &&
          r.size() == 2 && number(r[0].text, &lo) && number(r[1].text, &hi) && lo < hi) {
        PanelSlider sl;
        sl.label = name;
        sl.define = m[1].text;
        sl.min = lo / scale;
        sl.max = hi / scale;
        if (sl.min > sl.max) std::swap(sl.min, sl.max);
        sl.step = 1 / std::abs(scale);
        sl.value = number(value, &v) ? v / scale : sl.min;
        out.push_back(std::move(sl));
      }
    }
    type.clear(), name.clear(), minmax.clear(), value.clear(), message.clear();
  };
  for_each_physical_line(text, [&](uint32_t, std::string_view line, bool) {
    std::string key;
    const std::optional<size_t> colon = command_of(line, &key);
    if (!colon) return;
    std::string_view rest = line.substr(*colon + 1);
    while (!rest.empty() && is_space(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && (is_space(rest.back()) || rest.back() == '\r')) rest.remove_suffix(1);
    if (key == "type") {
      finish();
      type = std::string(rest);
    } else if (key == "name") {
      name = std::string(rest);
    } else if (key == "min/max") {
      minmax = std::string(rest);
    } else if (key == "value") {
      value = std::string(rest);
    } else if (key == "message") {
      message = std::string(rest);
    }
  });
  finish();
  return out;
}

}  // namespace sylva::lsys
