// sylva_module.cpp — the `sylva` Python module (app/python/README.md): grammars, growth,
// skeletons as zero-copy numpy views, glTF export and the CPU renderer.
//
// Boundaries, as everywhere in sylva: errors are values in C++ and become Python
// exceptions here, each with a readable message (GrammarError carries file, line and
// column). Seeds cross as Python ints converted straight to uint64 — never through a
// float. Derivation, export and rendering run with the GIL released; the objects they
// read are immutable from Python (a Skeleton has no setters), so views stay valid.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "app/front/impostor.h"
#include "app/front/light.h"
#include "core/scene/scene_json.h"
#include "app/python/sylva_python.h"
#include "core/util/file_io.h"
#include "core/io/gltf.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/tessellate.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace sylva::python {

namespace {

// Exception types created at import (heap types owned by the module; never freed).
PyObject* g_grammar_error = nullptr;
PyObject* g_skeleton_error = nullptr;

// Raises `type(text)` with file/line/column/source_line attributes (None where the
// place is unknown).
void set_located_error(PyObject* type, const std::string& text, const std::string& message,
                       const std::string& file, uint32_t line, uint32_t column, const std::string& source_line) {
  py::object exc = py::reinterpret_borrow<py::object>(type)(text);
  exc.attr("file") = file.empty() ? py::object(py::none()) : py::object(py::str(file));
  exc.attr("line") = line ? py::object(py::int_(line)) : py::object(py::none());
  exc.attr("column") = line ? py::object(py::int_(column)) : py::object(py::none());
  exc.attr("message") = py::str(message);
  exc.attr("source_line") = py::str(source_line);
  PyErr_SetObject(type, exc.ptr());
}

}  // namespace

// Strips the trailing newline of a formatted diagnostic (str(e) should not end in one).
std::string chomp(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

// Raises OSError from a file's Diagnostic (FileNotFoundError etc. by errno, as open() would).
[[noreturn]] void throw_file_error(const Diagnostic& error) {
  const std::string text = chomp(error.format());
  if (error.error_number != 0) {
    py::object exc = py::reinterpret_borrow<py::object>(PyExc_OSError)(error.error_number, text, error.file);
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(exc.ptr())), exc.ptr());
  } else {
    PyErr_SetString(PyExc_OSError, text.c_str());
  }
  throw py::error_already_set();
}

// `os.fspath(path)` as the caller wrote it (kept verbatim: it is recorded in files).
std::string path_string(const std::filesystem::path& path) { return path.string(); }

GrammarFailure::GrammarFailure(sylva::Diagnostic d)
    : std::runtime_error(d.message), diagnostic(std::move(d)) {}

SkeletonFailure::SkeletonFailure(sylva::Diagnostic e)
    : std::runtime_error(e.message), error(std::move(e)) {}

std::optional<uint64_t> seed_from_python(const py::object& value) {
  if (value.is_none()) return std::nullopt;
  if (PyBool_Check(value.ptr()) || PyFloat_Check(value.ptr()))
    throw py::type_error("seed must be an int in [0, 2**64 - 1], not " +
                         std::string(Py_TYPE(value.ptr())->tp_name));
  // __index__ accepts int and numpy integers, rejects floats and strings (TypeError).
  py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    throw py::type_error("seed must be an int in [0, 2**64 - 1], not " + std::string(Py_TYPE(value.ptr())->tp_name));
  }
  const unsigned long long seed = PyLong_AsUnsignedLongLong(index.ptr());
  if (seed == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
    PyErr_Clear();
    PyErr_SetString(PyExc_OverflowError,
                    ("seed must be an int in [0, 2**64 - 1], got " + py::str(index).cast<std::string>()).c_str());
    throw py::error_already_set();
  }
  return static_cast<uint64_t>(seed);
}

std::optional<int64_t> steps_from_python(const py::object& value) {
  if (value.is_none()) return std::nullopt;
  if (PyBool_Check(value.ptr()) || PyFloat_Check(value.ptr()))
    throw py::type_error("steps must be an int >= 0, not " + std::string(Py_TYPE(value.ptr())->tp_name));
  py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    throw py::type_error("steps must be an int >= 0, not " + std::string(Py_TYPE(value.ptr())->tp_name));
  }
  int overflow = 0;
  const long long steps = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (steps == -1 && PyErr_Occurred()) throw py::error_already_set();
  if (overflow != 0 || steps < 0)
    throw py::value_error("steps must be an int >= 0, got " + py::str(index).cast<std::string>());
  return static_cast<int64_t>(steps);
}

SkinStyle skin_style_argument(const std::string& skin) {
  const std::optional<SkinStyle> style = parse_skin_style(skin);
  if (!style) throw py::value_error("skin must be \"smooth\" or \"paper\", got \"" + skin + "\"");
  return *style;
}

std::map<std::string, double> defines_from_python(const py::object& value) {
  std::map<std::string, double> defines;
  if (value.is_none()) return defines;
  if (!PyDict_Check(value.ptr())) throw py::type_error("defines must be a dict {name: number}");
  for (auto item : py::reinterpret_borrow<py::dict>(value)) {
    if (!PyUnicode_Check(item.first.ptr())) throw py::type_error("defines: every name must be a str");
    const std::string name = item.first.cast<std::string>();
    const double number = PyFloat_AsDouble(item.second.ptr());
    if (number == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw py::type_error("defines['" + name + "'] must be a number");
    }
    if (!std::isfinite(number)) throw py::value_error("defines['" + name + "'] must be finite");
    defines[name] = number;
  }
  return defines;
}

// ---------------------------------------------------------------------------------------
// Grammar

PyGrammar::PyGrammar(std::string grammar_text, std::string grammar_file)
    : text(std::move(grammar_text)), file(std::move(grammar_file)) {
  auto parsed_grammar = lsys::parse_grammar(text, file);
  if (!parsed_grammar) throw GrammarFailure(parsed_grammar.error());
  parsed = std::make_shared<const lsys::Grammar>(std::move(*parsed_grammar));
}

PyGrammar PyGrammar::from_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {  // a vlab object (docs/cpfg.md)
    // Parsed once, with the object's view file (its function sets' names are macros there):
    // the model's text alone would not parse.
    auto loaded = lsys::load_grammar(path);
    if (!loaded) throw GrammarFailure(loaded.error());
    std::string text = *loaded->text;
    PyGrammar g(std::move(text), path, std::make_shared<const lsys::Grammar>(std::move(*loaded)));
    g.vlab_object = true;
    return g;
  }
  Expected<std::string> read = read_text_file(path);
  if (!read) throw_file_error(read.error());
  return PyGrammar(std::move(*read), path);
}

std::shared_ptr<const lsys::Grammar> PyGrammar::with_defines(const std::map<std::string, double>& defines) const {
  if (defines.empty()) return parsed;
  lsys::ParseOptions options;
  options.define_overrides = defines;
  auto reparsed = vlab_object ? lsys::load_grammar(file, options) : lsys::parse_grammar(text, file, options);
  if (!reparsed) throw GrammarFailure(reparsed.error());
  return std::make_shared<const lsys::Grammar>(std::move(*reparsed));
}

namespace {

// Ctrl-C during long work with the GIL released (issue 32): the work's Progress reports
// (each derivation step, every 64 Ki modules, each turtle chunk: core/util/progress.h) take
// the GIL and run Python's signal handlers; the first exception one raises (KeyboardInterrupt)
// cancels the work and is raised again once it has stopped, so Ctrl-C lands within a step.
class PythonInterrupt {
 public:
  PythonInterrupt() = default;
  PythonInterrupt(const PythonInterrupt&) = delete;
  PythonInterrupt& operator=(const PythonInterrupt&) = delete;

  // A Progress for the work; this object must outlive it.
  Progress progress() {
    return Progress([this](double, std::string_view) { check(); }, &cancel_);
  }
  // With the GIL held: raises what a signal handler raised, if one did.
  void raise_if_interrupted() {
    if (error_) throw std::move(*error_);
  }

 private:
  void check() {
    if (cancel_.load(std::memory_order_relaxed)) return;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      error_.emplace();  // takes the pending exception
      cancel_.store(true);
    }
  }

  std::atomic<bool> cancel_{false};
  std::optional<py::error_already_set> error_;
};

lsys::DeriveOptions derive_options(const py::object& steps, const py::object& seed, uint64_t max_modules) {
  lsys::DeriveOptions options;
  options.steps = steps_from_python(steps);
  options.seed = seed_from_python(seed);
  if (max_modules == 0) throw py::value_error("max_modules must be > 0");
  options.max_modules = max_modules;
  return options;
}

// The scene a grammar grows in (light.md): None, or the path of a .scene.json whose
// plants grow beside it in its light. Raises what render() raises for a bad scene.
std::optional<Scene> light_scene_from_python(const py::object& scene) {
  if (scene.is_none()) return std::nullopt;
  if (!py::isinstance<py::str>(scene) && !py::hasattr(scene, "__fspath__"))
    throw py::type_error("scene must be None or the path of a .scene.json scene, got " +
                         std::string(py::str(py::type::handle_of(scene).attr("__name__"))));
  const std::string path = path_string(scene.cast<std::filesystem::path>());
  Expected<Scene> read = read_scene_file(path);
  if (!read) {
    if (read.error().error_number != 0 || read.error().loc.line == 0) throw_file_error(read.error());
    throw py::value_error(chomp(read.error().format()));
  }
  return std::move(*read);
}

// Grows as `sylva grow [--scene FILE]` does: the GIL released, interruptible, the
// interpretation-depth warning raised as a RuntimeWarning.
GrowResult grow_for_python(const PyGrammar& self, const py::object& steps, const py::object& seed,
                           const py::object& defines_object, uint64_t max_modules, const py::object& scene_object) {
  lsys::DeriveOptions options = derive_options(steps, seed, max_modules);
  const std::map<std::string, double> defines = defines_from_python(defines_object);
  const std::optional<Scene> scene = light_scene_from_python(scene_object);
  PythonInterrupt interrupt;
  options.progress = interrupt.progress();
  std::optional<sylva::Diagnostic> failure;
  std::optional<GrowResult> result;
  uint64_t still_expandable = 0;
  int max_depth = 0;
  {
    py::gil_scoped_release release;
    try {
      std::shared_ptr<const lsys::Grammar> grammar = self.with_defines(defines);
      auto grown = grow(*grammar, options, self.file, defines, {&cpu_light_oracle(), scene ? &*scene : nullptr});
      if (grown) {
        still_expandable = grown->interpret.still_expandable;
        max_depth = grammar->max_depth;
        result = std::move(*grown);
      } else {
        failure = grown.error();
      }
    } catch (const GrammarFailure& e) {
      failure = e.diagnostic;
    }
  }
  interrupt.raise_if_interrupted();
  if (failure) throw GrammarFailure(*failure);
  if (still_expandable != 0) {
    const std::string message = self.file + ": the interpretation stopped at maximum depth " +
                                std::to_string(max_depth) + " with " + std::to_string(still_expandable) +
                                " modules still expandable";
    if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) throw py::error_already_set();
  }
  return std::move(*result);
}

Skeleton grammar_grow(const PyGrammar& self, const py::object& steps, const py::object& seed,
                      const py::object& defines_object, uint64_t max_modules, const py::object& scene) {
  return std::move(grow_for_python(self, steps, seed, defines_object, max_modules, scene).skeleton);
}

// The skeleton and the light queries of the grown word: an (n, 7) float64 array of
// [x, y, z, q, dx, dy, dz] per ?E in word order (see the docstring).
py::tuple grammar_grow_with_queries(const PyGrammar& self, const py::object& steps, const py::object& seed,
                                    const py::object& defines_object, uint64_t max_modules, const py::object& scene) {
  GrowResult r = grow_for_python(self, steps, seed, defines_object, max_modules, scene);
  py::array_t<double> queries({static_cast<py::ssize_t>(r.queries.size()), py::ssize_t{7}});
  auto q = queries.mutable_unchecked<2>();
  for (size_t i = 0; i < r.queries.size(); ++i) {
    const GrowQuery& g = r.queries[i];
    const double row[7] = {g.position.x, g.position.y, g.position.z, g.q, g.toward.x, g.toward.y, g.toward.z};
    for (py::ssize_t k = 0; k < 7; ++k) q(static_cast<py::ssize_t>(i), k) = row[k];
  }
  return py::make_tuple(py::cast(std::move(r.skeleton)), queries);
}

std::string grammar_derive(const PyGrammar& self, const py::object& steps, const py::object& seed,
                           const py::object& defines_object, uint64_t max_modules, const py::object& scene_object) {
  lsys::DeriveOptions options = derive_options(steps, seed, max_modules);
  const std::map<std::string, double> defines = defines_from_python(defines_object);
  const std::optional<Scene> scene = light_scene_from_python(scene_object);
  PythonInterrupt interrupt;
  options.progress = interrupt.progress();
  std::optional<sylva::Diagnostic> failure;
  std::string text;
  {
    py::gil_scoped_release release;
    try {
      std::shared_ptr<const lsys::Grammar> grammar = self.with_defines(defines);
      auto word = derive_word(*grammar, options, {&cpu_light_oracle(), scene ? &*scene : nullptr});
      if (word)
        text = lsys::print_word(*word, grammar->symbols);
      else
        failure = word.error();
    } catch (const GrammarFailure& e) {
      failure = e.diagnostic;
    }
  }
  interrupt.raise_if_interrupted();
  if (failure) throw GrammarFailure(*failure);
  return text;
}

py::dict defines_dict(const std::map<std::string, double>& defines) {
  py::dict d;
  for (const auto& [name, value] : defines) d[py::str(name)] = value;
  return d;
}

// ---------------------------------------------------------------------------------------
// Skeleton

// The chains as numpy records (see the `chains` docstring).
struct ChainRecord {
  int32_t first_joint;
  int32_t joint_count;
  int32_t parent_chain;  // -1: a root chain
  int32_t parent_joint;  // joint index within the parent chain; -1 for a root chain
};

// The leaves as numpy records (see the `leaves` docstring).
struct LeafRecord {
  int32_t first_vertex;  // into leaf_vertices
  int32_t vertex_count;
  int32_t chain;         // the joint it hangs from; -1: none
  int32_t joint;
  uint32_t material;       // its front's where it has a back of its own
  uint32_t back_material;  // seen from behind (a cpfg double-sided surface's); else `material`
};

int32_t checked_index(uint64_t value, const char* what) {
  if (value > static_cast<uint64_t>(std::numeric_limits<int32_t>::max()))
    throw py::value_error(std::string("the skeleton has too many ") + what + " for int32 indices");
  return static_cast<int32_t>(value);
}

// A read-only view of a member of every Joint (stride sizeof(Joint)) that keeps `owner`
// alive through the array's base.
template <class T>
py::array joint_view(const py::object& owner, const Skeleton& skeleton, const T* first, std::vector<py::ssize_t> shape,
                     std::vector<py::ssize_t> strides) {
  py::array view = skeleton.joints.empty()
                       ? py::array(py::dtype::of<T>(), shape, strides)
                       : py::array(py::dtype::of<T>(), shape, strides, first, owner);
  view.attr("setflags")("write"_a = false);
  return view;
}

py::array skeleton_positions(const py::object& self) {
  const Skeleton& sk = self.cast<const Skeleton&>();
  const auto n = static_cast<py::ssize_t>(sk.joints.size());
  const double* first = sk.joints.empty() ? nullptr : &sk.joints[0].position_m[0];
  return joint_view(self, sk, first, {n, 3}, {static_cast<py::ssize_t>(sizeof(Joint)), sizeof(double)});
}

py::array skeleton_radii(const py::object& self) {
  const Skeleton& sk = self.cast<const Skeleton&>();
  const auto n = static_cast<py::ssize_t>(sk.joints.size());
  const double* first = sk.joints.empty() ? nullptr : &sk.joints[0].radius_m;
  return joint_view(self, sk, first, {n}, {static_cast<py::ssize_t>(sizeof(Joint))});
}

py::array skeleton_materials(const py::object& self) {
  const Skeleton& sk = self.cast<const Skeleton&>();
  const auto n = static_cast<py::ssize_t>(sk.joints.size());
  const uint32_t* first = sk.joints.empty() ? nullptr : &sk.joints[0].material;
  return joint_view(self, sk, first, {n}, {static_cast<py::ssize_t>(sizeof(Joint))});
}

py::array_t<int32_t> skeleton_segments(const Skeleton& sk) {
  const auto count = static_cast<py::ssize_t>(sk.segment_count());
  checked_index(sk.joints.size(), "joints");
  py::array_t<int32_t> segments({count, py::ssize_t{2}});
  auto out = segments.mutable_unchecked<2>();
  py::ssize_t s = 0;
  for (const Chain& chain : sk.chains) {
    for (uint32_t k = 1; k < chain.joint_count; ++k, ++s) {
      uint32_t start = chain.first_joint + k - 1;
      // A branch's first segment starts at the joint it grows from, so the segments
      // form one connected tree per root chain (the joints are at the same place).
      if (k == 1 && chain.parent) start = sk.chains[chain.parent->chain].first_joint + chain.parent->joint;
      out(s, 0) = static_cast<int32_t>(start);
      out(s, 1) = static_cast<int32_t>(chain.first_joint + k);
    }
  }
  return segments;
}

py::array_t<ChainRecord> skeleton_chains(const Skeleton& sk) {
  checked_index(sk.joints.size(), "joints");
  checked_index(sk.chains.size(), "chains");
  py::array_t<ChainRecord> chains(static_cast<py::ssize_t>(sk.chains.size()));
  auto out = chains.mutable_unchecked<1>();
  for (size_t c = 0; c < sk.chains.size(); ++c) {
    const Chain& chain = sk.chains[c];
    ChainRecord& r = out(static_cast<py::ssize_t>(c));
    r.first_joint = static_cast<int32_t>(chain.first_joint);
    r.joint_count = static_cast<int32_t>(chain.joint_count);
    r.parent_chain = chain.parent ? static_cast<int32_t>(chain.parent->chain) : -1;
    r.parent_joint = chain.parent ? static_cast<int32_t>(chain.parent->joint) : -1;
  }
  return chains;
}

py::array_t<LeafRecord> skeleton_leaves(const Skeleton& sk) {
  checked_index(sk.leaves.size(), "leaves");
  py::array_t<LeafRecord> leaves(static_cast<py::ssize_t>(sk.leaves.size()));
  auto out = leaves.mutable_unchecked<1>();
  uint64_t first = 0;
  for (size_t l = 0; l < sk.leaves.size(); ++l) {
    const Leaf& leaf = sk.leaves[l];
    LeafRecord& r = out(static_cast<py::ssize_t>(l));
    r.first_vertex = checked_index(first, "leaf vertices");
    r.vertex_count = checked_index(leaf.vertices_m.size(), "leaf vertices");
    r.chain = leaf.joint ? static_cast<int32_t>(leaf.joint->chain) : -1;
    r.joint = leaf.joint ? static_cast<int32_t>(leaf.joint->joint) : -1;
    r.material = leaf.material;
    r.back_material = leaf.back_material.value_or(leaf.material);
    first += leaf.vertices_m.size();
  }
  return leaves;
}

py::array_t<double> skeleton_leaf_vertices(const Skeleton& sk) {
  size_t count = 0;
  for (const Leaf& leaf : sk.leaves) count += leaf.vertices_m.size();
  py::array_t<double> vertices({static_cast<py::ssize_t>(count), py::ssize_t{3}});
  auto out = vertices.mutable_unchecked<2>();
  py::ssize_t v = 0;
  for (const Leaf& leaf : sk.leaves)
    for (const auto& p : leaf.vertices_m) {
      for (py::ssize_t k = 0; k < 3; ++k) out(v, k) = p[static_cast<size_t>(k)];
      ++v;
    }
  return vertices;
}

Skeleton skeleton_from_json(const std::string& text, const std::string& file) {
  Expected<Skeleton> read = read_skeleton_json(text, file);
  if (!read) throw SkeletonFailure(std::move(read.error()));
  return std::move(*read);
}

Skeleton skeleton_from_file(const std::filesystem::path& path_in) {
  const std::string path = path_string(path_in);
  Expected<std::string> read = read_text_file(path);
  if (!read) throw_file_error(read.error());
  return skeleton_from_json(*read, path);
}

// The files a plant is made from, which nothing made from it may overwrite
// (docs/limits.md, "Outputs"): the grammar it grew from. (The CLI refuses every file its
// command read; a Python session lives too long for that, so each call names its own.)
std::vector<std::string> plant_inputs(const Skeleton& sk) {
  if (sk.source.grammar.empty() || sk.source.grammar.front() == '<') return {};
  return {sk.source.grammar};
}

void skeleton_save(const Skeleton& sk, const std::filesystem::path& path) {
  const std::string target = path_string(path);
  if (Status allowed = check_not_an_input(target, plant_inputs(sk)); !allowed) throw_file_error(allowed.error());
  const std::string json = write_skeleton_json(sk);
  Status written;
  {
    py::gil_scoped_release release;
    written = write_file_atomically(target, json);
  }
  if (!written) throw_file_error(written.error());
}

std::string skeleton_repr(const Skeleton& sk) {
  std::string name = sk.source.grammar.empty() ? "" : std::filesystem::path(sk.source.grammar).filename().string() + " ";
  return "<sylva.Skeleton " + name + "seed=" + std::to_string(sk.source.seed) + " steps=" +
         std::to_string(sk.source.steps) + ": " + std::to_string(sk.chains.size()) + " chains, " +
         std::to_string(sk.joints.size()) + " joints, " + std::to_string(sk.segment_count()) + " segments>";
}

// ---------------------------------------------------------------------------------------
// glTF export

std::string plant_name(const Skeleton& sk) {
  std::string stem = std::filesystem::path(sk.source.grammar).stem().string();
  if (stem.empty() || stem.front() == '<') stem = "plant";
  return stem;
}

// A Skeleton or a sequence of Skeletons.
std::vector<const Skeleton*> skeleton_list(const py::object& plants) {
  std::vector<const Skeleton*> list;
  if (py::isinstance<Skeleton>(plants)) {
    list.push_back(&plants.cast<const Skeleton&>());
    return list;
  }
  if (!py::isinstance<py::sequence>(plants) || py::isinstance<py::str>(plants))
    throw py::type_error("plants must be a sylva.Skeleton or a sequence of them");
  for (auto item : py::reinterpret_borrow<py::sequence>(plants)) {
    if (!py::isinstance<Skeleton>(item)) throw py::type_error("plants must be a sylva.Skeleton or a sequence of them");
    list.push_back(&item.cast<const Skeleton&>());
  }
  return list;
}

// A per-plant argument: None, or a sequence of exactly `count` items.
py::sequence per_plant(const py::object& value, size_t count, const char* name) {
  if (!py::isinstance<py::sequence>(value) || py::isinstance<py::str>(value))
    throw py::type_error(std::string(name) + " must be a sequence with one entry per plant");
  py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
  if (seq.size() != count)
    throw py::value_error(std::string(name) + " has " + std::to_string(seq.size()) + " entries for " +
                          std::to_string(count) + " plants");
  return seq;
}

// The `bark` argument of export_gltf: a dict with the keys of docs/spec/scene.md's "bark".
Bark bark_from_dict(const py::object& value) {
  if (!py::isinstance<py::dict>(value))
    throw py::type_error("bark must be a dict with keys albedo, height, relief_depth, u_repeat, v_per_metre");
  Bark bark;
  for (const auto& [key_object, item] : py::reinterpret_borrow<py::dict>(value)) {
    const std::string key = py::str(key_object);
    const py::object v = py::reinterpret_borrow<py::object>(item);
    if (key == "albedo") {
      if (py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__")) {
        bark.albedo_texture = path_string(cast_argument<std::filesystem::path>(v, "bark['albedo']", "a path"));
      } else {
        const auto rgb =
            cast_argument<std::vector<double>>(v, "bark['albedo']", "a path or an (r, g, b) linear colour");
        if (rgb.size() != 3) throw py::value_error("bark['albedo'] must be a path or an (r, g, b) linear colour");
        bark.albedo_rgb = glm::dvec3(rgb[0], rgb[1], rgb[2]);
      }
    } else if (key == "height") {
      bark.height_texture = path_string(cast_argument<std::filesystem::path>(v, "bark['height']", "a path"));
    } else if (key == "relief_depth") {
      bark.relief_depth_m = cast_argument<double>(v, "bark['relief_depth']", "a number (metres)");
      if (!std::isfinite(bark.relief_depth_m) || bark.relief_depth_m < 0)
        throw py::value_error("bark['relief_depth'] must be a finite number >= 0 (metres)");
    } else if (key == "u_repeat" || key == "v_per_metre") {
      const double x = cast_argument<double>(v, "bark['" + key + "']", "a number");
      if (!std::isfinite(x) || x <= 0) throw py::value_error("bark['" + key + "'] must be a finite number > 0");
      (key == "u_repeat" ? bark.u_repeat : bark.v_per_metre) = x;
    } else {
      throw py::value_error("bark: unknown key '" + key + "' (albedo, height, relief_depth, u_repeat, v_per_metre)");
    }
  }
  return bark;
}

void python_export_gltf(const py::object& plants, const std::filesystem::path& path, bool mesh, int segments_around,
                        bool instancing, const py::object& names, const py::object& positions,
                        const py::object& rotate_y_deg, const py::object& scales, const py::object& bark,
                        const std::string& extras, const std::string& skin, bool rig, int max_joints,
                        const py::object& animation, bool wind_data, int lod, const std::string& compress) {
  const SkinStyle style = skin_style_argument(skin);
  const std::vector<const Skeleton*> skeletons = skeleton_list(plants);
  if (skeletons.empty()) throw py::value_error("export_gltf needs at least one plant");
  if (segments_around < 3) throw py::value_error("segments_around must be >= 3");
  std::vector<GltfPlant> gltf_plants(skeletons.size());
  for (size_t i = 0; i < skeletons.size(); ++i) {
    gltf_plants[i].skeleton = *skeletons[i];
    gltf_plants[i].name = plant_name(*skeletons[i]);
    gltf_plants[i].skin = style;
  }
  if (!names.is_none()) {
    py::sequence seq = per_plant(names, skeletons.size(), "names");
    for (size_t i = 0; i < skeletons.size(); ++i)
      gltf_plants[i].name = cast_argument<std::string>(seq[i], "names[" + std::to_string(i) + "]", "a str");
  }
  if (!positions.is_none()) {
    py::sequence seq = per_plant(positions, skeletons.size(), "positions");
    for (size_t i = 0; i < skeletons.size(); ++i) {
      auto p = cast_argument<std::vector<double>>(seq[i], "positions[" + std::to_string(i) + "]",
                                                  "an (x, y, z) sequence of numbers");
      if (p.size() != 3) throw py::value_error("positions: every entry must be (x, y, z) in metres");
      for (int k = 0; k < 3; ++k) gltf_plants[i].position_m[k] = p[static_cast<size_t>(k)];
    }
  }
  if (!rotate_y_deg.is_none()) {
    py::sequence seq = per_plant(rotate_y_deg, skeletons.size(), "rotate_y_deg");
    for (size_t i = 0; i < skeletons.size(); ++i)
      gltf_plants[i].rotate_y_deg =
          cast_argument<double>(seq[i], "rotate_y_deg[" + std::to_string(i) + "]", "a number (degrees)");
  }
  if (!scales.is_none()) {
    py::sequence seq = per_plant(scales, skeletons.size(), "scales");
    for (size_t i = 0; i < skeletons.size(); ++i)
      gltf_plants[i].scale = cast_argument<double>(seq[i], "scales[" + std::to_string(i) + "]", "a number");
  }
  if (!bark.is_none()) {
    if (!mesh) throw py::value_error("bark shapes the mesh: pass mesh=True too");
    const Bark b = bark_from_dict(bark);
    for (GltfPlant& p : gltf_plants) p.bark = b;
  }
  std::vector<std::string> inputs;
  for (const GltfPlant& p : gltf_plants) {
    for (std::string& input : plant_inputs(p.skeleton)) inputs.push_back(std::move(input));
    for (const auto* image : {&p.bark.albedo_texture, &p.bark.height_texture})
      if (*image) inputs.push_back(**image);
  }
  if (Status allowed = check_not_an_input(path_string(path), inputs); !allowed) throw_file_error(allowed.error());
  GltfExportOptions options;
  options.mesh = mesh;
  options.segments_around = segments_around;
  options.instancing = instancing;
  options.rig = rig;
  if (max_joints < 1 || max_joints > static_cast<int>(kMaxRigJoints))
    throw py::value_error("max_joints must be from 1 to " + std::to_string(kMaxRigJoints));
  options.max_joints = static_cast<uint32_t>(max_joints);
  options.wind_data = wind_data;
  if (lod < 0 || lod > static_cast<int>(kMaxLodLevels))
    throw py::value_error("lod must be from 0 (none) to " + std::to_string(kMaxLodLevels));
  options.lod = static_cast<uint32_t>(lod);
  if (lod > 0) options.card_renderer = cpu_card_renderer({});
  if (compress == "meshopt") options.compress = GltfCompression::meshopt;
  else if (compress != "none") throw py::value_error("compress must be \"none\" or \"meshopt\", got \"" + compress + "\"");
  // animation: True for the default sway, or a dict with the keys of a scene's "animation".
  if (!animation.is_none() && !(py::isinstance<py::bool_>(animation) && !animation.cast<bool>())) {
    SceneAnimation a;
    if (py::isinstance<py::dict>(animation)) {
      const std::string text = py::module_::import("json").attr("dumps")(animation).cast<std::string>();
      Expected<SceneAnimation> parsed = parse_animation_json(text, "animation");
      if (!parsed) throw py::value_error(chomp(parsed.error().format()));
      a = *parsed;
    } else if (!py::isinstance<py::bool_>(animation)) {
      throw py::type_error("animation must be True, False, None or a dict of a scene's animation keys");
    }
    options.animation = GltfWindClip{.sway = sway_parameters_of(a), .duration_s = a.duration_s, .fps = a.fps};
    options.wind_seed = a.seed;
  }
  if (extras == "full") options.extras = GltfExtras::full;
  else if (extras == "compact") options.extras = GltfExtras::compact;
  else if (extras == "none") options.extras = GltfExtras::none;
  else throw py::value_error("extras must be \"full\", \"compact\" or \"none\", got \"" + extras + "\"");
  Status exported;
  {
    py::gil_scoped_release release;
    exported = export_gltf(gltf_plants, path_string(path), options);
  }
  // A file that could not be read or written raises OSError (by errno, as open() would);
  // plants the export refuses (values beyond docs/limits.md) raise ValueError.
  if (!exported) {
    const Diagnostic& d = exported.error();
    if (d.error_number != 0 || d.message.rfind("cannot ", 0) == 0) throw_file_error(d);
    throw py::value_error(chomp(d.format()));
  }
}


const char* const kModuleDoc = R"doc(sylva: procedural plants from L-systems, scripted from Python.

A grammar (.lsys text) is derived into a word, the turtle turns the word into a
skeleton (chains of joints: position and radius in metres, Y up, material index), and
the skeleton exports to glTF 2.0 or renders on the CPU:

    import sylva
    g = sylva.Grammar.from_file("presets/elm.lsys")    # or sylva.Grammar(text)
    sk = g.grow(seed=7, steps=6)                        # keyword-only knobs
    print(sk.positions.shape, sk.radii.max())           # zero-copy numpy views
    sylva.export_gltf(sk, "elm.glb", mesh=True)

Classes: Grammar, Skeleton. Functions: export_gltf, render (the CPU ray caster).
Errors: GrammarError (a ValueError with .file, .line, .column),
SkeletonError (a ValueError, same attributes); file problems raise OSError.
Seeds are ints in [0, 2**64 - 1], carried exactly (never through a float).
Growing, deriving, exporting and rendering release the GIL, so threads run in parallel.
)doc";

}  // namespace

void bind_module(py::module_& m) {
  m.doc() = kModuleDoc;
  PYBIND11_NUMPY_DTYPE(ChainRecord, first_joint, joint_count, parent_chain, parent_joint);
  PYBIND11_NUMPY_DTYPE(LeafRecord, first_vertex, vertex_count, chain, joint, material, back_material);
  m.attr("__version__") = "0.1.0";

  // --- exceptions -----------------------------------------------------------------------
  g_grammar_error = PyErr_NewExceptionWithDoc(
      "sylva.GrammarError",
      "A grammar that cannot be parsed or derived, or a define the grammar does not have.\n\n"
      "A ValueError. str(e) is the full diagnostic: 'file:line:column: error: message', the\n"
      "source line and a caret. Attributes: file (str), line and column (1-based ints; None\n"
      "when the problem has no place in the text, e.g. an unknown define name), message\n"
      "(str, without the place), source_line (str).",
      PyExc_ValueError, nullptr);
  g_skeleton_error = PyErr_NewExceptionWithDoc(
      "sylva.SkeletonError",
      "A skeleton file or JSON text that is not a valid sylva-skeleton version 1 document.\n\n"
      "A ValueError with attributes file, line, column (None where unknown) and message.",
      PyExc_ValueError, nullptr);
  if (!g_grammar_error || !g_skeleton_error) throw py::error_already_set();
  // A mesh that cannot fit is refused before anything is allocated (docs/limits.md): the
  // arguments asked too much, a ValueError as the module's README promises.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const MeshTooLarge& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const py::cast_error& e) {
      // A conversion cast_argument does not cover: still a TypeError, not a RuntimeError.
      PyErr_SetString(PyExc_TypeError, (std::string("an argument has the wrong type: ") + e.what()).c_str());
    }
  });
  for (PyObject* type : {g_grammar_error, g_skeleton_error}) {
    py::object t = py::reinterpret_borrow<py::object>(type);
    t.attr("file") = py::none();
    t.attr("line") = py::none();
    t.attr("column") = py::none();
    t.attr("message") = "";
    t.attr("source_line") = "";
  }
  m.attr("GrammarError") = py::reinterpret_borrow<py::object>(g_grammar_error);
  m.attr("SkeletonError") = py::reinterpret_borrow<py::object>(g_skeleton_error);

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const GrammarFailure& e) {
      const sylva::Diagnostic& d = e.diagnostic;
      // A -D name the grammar lacks has no place: the message alone reads best.
      const std::string text = d.loc.line == 0 ? d.file + ": error: " + d.message : chomp(d.format());
      set_located_error(g_grammar_error, text, d.message, d.file, d.loc.line, d.loc.column,
                        d.source_line.value_or(""));
    } catch (const SkeletonFailure& e) {
      const sylva::Diagnostic& s = e.error;
      set_located_error(g_skeleton_error, chomp(s.format()), s.message, s.file, s.loc.line, s.loc.column, "");
    }
  });

  // Both classes are registered before any method so signatures name them (sylva.Skeleton).
  py::class_<PyGrammar> grammar_class(m, "Grammar", R"doc(A parsed L-system grammar (.lsys text), ready to derive and grow.

Grammar(text, *, file="<string>") parses text; Grammar.from_file(path) reads a file.
Parse errors raise GrammarError with the file, line and column. The text is kept:
grow()/derive() with `defines` re-parse it with those #define overrides (they are
applied at parse time, exactly as `sylva grow -D NAME=VALUE` does).
A Grammar is immutable and may be used from several threads at once.)doc");
  py::class_<Skeleton> skeleton_class(m, "Skeleton", R"doc(A plant skeleton: chains of joints (metres, Y up), as sylva-skeleton JSON describes.

Immutable. Array properties are numpy arrays:
  positions (J, 3) float64, radii (J,) float64, materials (J,) uint32 — read-only
      zero-copy views of the joints; each keeps the Skeleton alive.
  segments (S, 2) int32 — joint index pairs (start, end), one per segment.
  chains (C,) structured int32 records (first_joint, joint_count, parent_chain,
      parent_joint); parent_chain = parent_joint = -1 for a root chain.
Chain c owns joints[first_joint : first_joint + joint_count].
  leaves (L,) structured records (first_vertex, vertex_count, chain, joint int32, material
      uint32): the grammar's polygons (docs/spec/skeleton.md "Leaves"); chain = joint = -1 for a
      leaf on no joint. leaf_vertices (V, 3) float64 holds every leaf's vertices, leaf l
      owning leaf_vertices[first_vertex : first_vertex + vertex_count].
Make one with Grammar.grow(), Skeleton.from_file() or Skeleton.from_json().)doc");

  // --- Grammar --------------------------------------------------------------------------
  grammar_class.def(py::init([](std::string text, std::string file) { return PyGrammar(std::move(text), std::move(file)); }),
           "text"_a, py::kw_only(), "file"_a = "<string>",
           "Parses grammar text. `file` names it in error messages and in the skeleton's source.")
      .def_static(
          "from_file", [](const std::filesystem::path& path) { return PyGrammar::from_file(path_string(path)); },
          "path"_a,
          "Reads and parses a grammar file (str or os.PathLike). The path is recorded, as given,\n"
          "in grown skeletons. A missing file raises FileNotFoundError; bad text GrammarError.")
      .def_property_readonly("text", [](const PyGrammar& g) { return g.text; }, "The grammar's source text.")
      .def_property_readonly("file", [](const PyGrammar& g) { return g.file; },
                             "The file name used in messages and recorded in skeletons.")
      .def_property_readonly(
          "defines",
          [](const PyGrammar& g) {
            py::dict d;
            for (const lsys::Define& def : g.parsed->defines) d[py::str(def.name)] = def.value;
            return d;
          },
          "The grammar's #defines as {name: value} (values as written in the file).")
      .def_property_readonly("seed", [](const PyGrammar& g) { return g.parsed->seed; },
                             "The default seed (the grammar's `seed:` line, else 1).")
      .def_property_readonly("steps", [](const PyGrammar& g) { return g.parsed->steps; },
                             "The default number of derivation steps (`derivation length:`).");
  {
    // steps/seed/defines are converted by hand (exact uint64 seeds, numpy integers), so
    // pybind11 would show them as `object`: the signatures are written out instead.
    py::options signatures;
    signatures.disable_function_signatures();
    grammar_class.def("grow", &grammar_grow, py::kw_only(), "steps"_a = py::none(), "seed"_a = py::none(),
           "defines"_a = py::none(), "max_modules"_a = uint64_t{50'000'000}, "scene"_a = py::none(),
           R"doc(grow(self, *, steps: int | None = None, seed: int | None = None, defines: dict[str, float] | None = None, max_modules: int = 50000000, scene: str | os.PathLike | None = None) -> sylva.Skeleton

Derives the grammar and builds its skeleton with the turtle (what `sylva grow` does).

Keyword-only:
  steps        derivation steps (int >= 0; default: the grammar's `derivation length:`)
  seed         random seed, an int in [0, 2**64 - 1] (default: the grammar's `seed:`)
  defines      {name: number} overriding #defines; a name the grammar lacks is a
               GrammarError (line and column None)
  max_modules  stop with GrammarError if a word would exceed this many modules
  scene        a .scene.json: a grammar with light queries (?E) grows at its origin in its
               light and environment, beside its plants (`sylva grow --scene`); None: the
               default sun over the ground y = 0 (docs/spec/light.md)
Returns a Skeleton whose JSON equals `sylva grow` output byte for byte. The GIL is
released while growing. A RuntimeWarning reports an interpretation cut at max depth.)doc");
    grammar_class.def("grow_with_queries", &grammar_grow_with_queries, py::kw_only(), "steps"_a = py::none(),
           "seed"_a = py::none(), "defines"_a = py::none(), "max_modules"_a = uint64_t{50'000'000},
           "scene"_a = py::none(),
           R"doc(grow_with_queries(self, *, steps=None, seed=None, defines=None, max_modules=50000000, scene=None) -> tuple[sylva.Skeleton, numpy.ndarray]

grow() and the light queries of the grown word: an (n, 7) float64 array, one row per
?E module in word order, [x, y, z, q, dx, dy, dz] — where the turtle stood at the query
(metres, the plant's frame), its last answer q (0..1, the light reaching a small sphere
there over the open sky's) and the unit direction the light came from (zeros for ?E(q)
and where no light arrived). A grammar without ?E gives an empty (0, 7) array.)doc");
    grammar_class.def("derive", &grammar_derive, py::kw_only(), "steps"_a = py::none(), "seed"_a = py::none(),
           "defines"_a = py::none(), "max_modules"_a = uint64_t{50'000'000}, "scene"_a = py::none(),
           "derive(self, *, steps: int | None = None, seed: int | None = None, defines: dict[str, float] | None = None, "
           "max_modules: int = 50000000, scene: str | os.PathLike | None = None) -> str\n\n"
           "Derives the grammar's word and returns it as `sylva derive` prints it (without the\n"
           "final newline). Same keyword-only knobs as grow(); the GIL is released.");
  }
  grammar_class.def("__repr__", [](const PyGrammar& g) {
        return "<sylva.Grammar " + g.file + ": " + std::to_string(g.parsed->productions.size()) + " productions, " +
               std::to_string(g.parsed->defines.size()) + " defines>";
      });

  // --- Skeleton -------------------------------------------------------------------------
  skeleton_class
      .def_static("from_file", &skeleton_from_file, "path"_a,
                  "Reads a .skel.json file. Invalid content raises SkeletonError naming chain, joint,\n"
                  "line and column; an unreadable file raises OSError.")
      .def_static("from_json", &skeleton_from_json, "text"_a, "file"_a = "<string>",
                  "Parses sylva-skeleton JSON text (`file` only names it in errors).")
      .def("to_json", &write_skeleton_json,
           "The sylva-skeleton JSON text, byte-identical to what `sylva grow -o` writes.")
      .def("save", &skeleton_save, "path"_a,
           "Writes to_json() to `path` atomically (readers never see a partial file).")
      .def_property_readonly("positions", &skeleton_positions,
                             "(J, 3) float64 joint positions in metres, Y up. Read-only view, no copy.")
      .def_property_readonly("radii", &skeleton_radii, "(J,) float64 joint radii in metres (0 is a tip). Read-only view.")
      .def_property_readonly("materials", &skeleton_materials,
                             "(J,) uint32 material index of the segment ending at each joint. Read-only view.")
      .def_property_readonly(
          "segments", &skeleton_segments,
          "(S, 2) int32 joint index pairs (start, end), chain by chain, one per segment.\n"
          "Within a chain a segment joins consecutive joints; a branch's first segment starts\n"
          "at its parent joint instead of the branch's own first joint (same position), so\n"
          "the segments form one connected tree per root. A new array on every access.")
      .def_property_readonly(
          "chains", &skeleton_chains,
          "(C,) numpy structured array, fields first_joint, joint_count, parent_chain,\n"
          "parent_joint (int32; parents -1 for a root chain). Parents come before children.\n"
          "E.g. sk.chains['parent_chain'], or for c in sk.chains: c['first_joint'].")
      .def_property_readonly(
          "leaves", &skeleton_leaves,
          "(L,) numpy structured array, fields first_vertex, vertex_count, chain, joint (int32;\n"
          "-1 for a leaf on no joint), material and back_material (uint32; the material seen from\n"
          "behind, the same as material unless a cpfg double-sided surface gives it its own, docs/leaves.md):\n"
          "the leaves (docs/spec/skeleton.md), one per polygon of the grammar. A new array on every access.")
      .def_property_readonly("leaf_vertices", &skeleton_leaf_vertices,
                             "(V, 3) float64 every leaf's vertices in metres, leaf after leaf. A new array.")
      .def_property_readonly("leaf_count", [](const Skeleton& sk) { return sk.leaves.size(); }, "Number of leaves L.")
      .def_property_readonly("joint_count", [](const Skeleton& sk) { return sk.joints.size(); }, "Number of joints J.")
      .def_property_readonly("chain_count", [](const Skeleton& sk) { return sk.chains.size(); }, "Number of chains C.")
      .def_property_readonly("segment_count", &Skeleton::segment_count, "Number of segments S = sum(joint_count - 1).")
      .def_property_readonly("grammar", [](const Skeleton& sk) { return sk.source.grammar; },
                             "The grammar path it was grown from, as given (source.grammar).")
      .def_property_readonly("seed", [](const Skeleton& sk) { return sk.source.seed; },
                             "The 64-bit seed it was grown with (an exact int).")
      .def_property_readonly("steps", [](const Skeleton& sk) { return sk.source.steps; }, "The derivation steps.")
      .def_property_readonly("defines", [](const Skeleton& sk) { return defines_dict(sk.source.defines); },
                             "The #define overrides it was grown with, {name: value}.")
      .def("__repr__", &skeleton_repr)
      .def(py::pickle([](const Skeleton& sk) { return write_skeleton_json(sk); },
                      [](const std::string& json) { return skeleton_from_json(json, "<pickle>"); }));

  // --- functions ------------------------------------------------------------------------
  py::options signatures;  // per-plant arguments are any sequences: the signature is written out
  signatures.disable_function_signatures();
  m.def("export_gltf", &python_export_gltf, "plants"_a, "path"_a, py::kw_only(), "mesh"_a = false,
        "segments_around"_a = 8, "instancing"_a = false, "names"_a = py::none(), "positions"_a = py::none(),
        "rotate_y_deg"_a = py::none(), "scales"_a = py::none(), "bark"_a = py::none(), "extras"_a = "full",
        "skin"_a = "smooth", "rig"_a = false, "max_joints"_a = static_cast<int>(kDefaultRigJoints),
        "animation"_a = py::none(), "wind_data"_a = false, "lod"_a = 0, "compress"_a = "none",
        R"doc(export_gltf(plants: Skeleton | Sequence[Skeleton], path: str | os.PathLike, *, mesh: bool = False, segments_around: int = 8, instancing: bool = False, names: Sequence[str] | None = None, positions: Sequence[tuple[float, float, float]] | None = None, rotate_y_deg: Sequence[float] | None = None, scales: Sequence[float] | None = None, bark: dict | None = None, extras: str = "full", skin: str = "smooth", rig: bool = False, max_joints: int = 128, animation: bool | dict | None = None, wind_data: bool = False, lod: int = 0, compress: str = "none") -> None

Writes plants to a glTF 2.0 file, binary (.glb) or JSON (.gltf) by extension.

plants: a Skeleton or a sequence of Skeletons, one node each, carrying the skeleton
as a LINES mesh and the exact skeleton document in the node's extras["sylva"].
Keyword-only:
  mesh             also write the skinned frusta as a triangle mesh (see bark)
  segments_around  columns around each frustum of that mesh (>= 3)
  instancing       repeated identical plants as EXT_mesh_gpu_instancing
  names            node names (default: the grammar file's stem, e.g. "elm")
  positions        per plant (x, y, z) node translation in metres
  rotate_y_deg     per plant rotation about +Y in degrees
  scales           per plant uniform scale
  bark             the mesh's bark for every plant (needs mesh=True), a dict with the
                   keys of a scene's "bark": albedo (a PNG/JPEG path, embedded as the
                   base colour texture, or an (r, g, b) linear colour for material 0),
                   height (a height map path, baked into a tangent-space normal map),
                   relief_depth (metres, default 0.02), u_repeat (texture repeats around
                   the stem, default 1), v_per_metre (repeats per metre along it,
                   default 1). TEXCOORD_0 becomes (u*u_repeat, v_m*v_per_metre).
                   e.g. bark=dict(albedo="presets/textures/bark.png",
                   height="presets/textures/bark_height.png", u_repeat=2)
  extras           how extras["sylva"] holds the skeleton (docs/gltf.md): "full" (default
                   here: every number as JSON, for readers of the JSON), "compact" (the
                   large arrays as bufferViews of raw float64/uint32, bit-exact and a few
                   times smaller: `sylva export`'s default) or "none" (a plain mesh)
  skin             how chains meet in the mesh and extras' skinning: "smooth" (collars,
                   domes, rounded bends) or "paper" (Bhagvat et al. 2009's mitred chains)
  rig              skin the mesh to a glTF skin for wind (needs mesh=True, not with
                   instancing): joints along the first branch orders (docs/gltf.md)
  max_joints       the rig's joints per plant, root included, 1 to 1024
  animation        with rig=True: True for the default sway, or a dict with the keys of a
                   scene's "animation" (wind, amplitude_deg, frequency_hz, seed, fps,
                   duration_s, ...): one looping clip "wind", frequencies rounded to whole
                   cycles per duration_s; plant i sways as plant i of a scene
  wind_data        per-vertex wind data for shaders (needs mesh=True): TEXCOORD_2 =
                   (pivot x, pivot y), TEXCOORD_3 = (pivot z, level + phase)
  lod              levels of detail NAME_LOD0 ... NAME_LODn (needs mesh=True), 0 (none) to
                   6: each re-meshed with about a quarter of the triangles before, the last
                   crossed impostor cards drawn by the CPU ray caster
  compress         "none" (default) or "meshopt": the vertex and index data encoded with
                   EXT_meshopt_compression (lossless, then required; three.js, Babylon and
                   glTFast decode it, Blender 3.4 and Godot cannot)
The mesh has one material per material index the plants use. The file is written
atomically; a file that cannot be read or written (a missing texture, a missing folder,
a FIFO or read-only target) raises OSError, plants beyond the limits (docs/limits.md)
ValueError, each with the reason naming the file, and nothing is written. The GIL is released while writing.)doc");
  signatures.enable_function_signatures();

  bind_render(m);
}

}  // namespace sylva::python

PYBIND11_MODULE(sylva, m) {
  // The skeleton's arrays are numpy arrays: without numpy pybind11 would fail with a bare
  // "ImportError: initialization failed". Say what is missing and where to get it.
  try {
    py::module_::import("numpy.core.multiarray");
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    const std::string python = py::str(py::module_::import("sys").attr("executable"));
    throw py::import_error("sylva needs numpy, which " + python + " cannot import (" + e.what() +
                           "); on Debian: apt-get install python3-numpy, and run /usr/bin/python3");
  }
  sylva::python::bind_module(m);
}
