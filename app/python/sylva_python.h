// sylva_python.h — shared pieces of the `sylva` Python module's translation units.
//
// C++ failures cross to Python as the exception types below, translated once (in
// sylva_module.cpp) into sylva.GrammarError / sylva.SkeletonError with file, line and
// column attributes. Argument converters keep Python ints exact (seeds are uint64).
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/geometry/skeleton.h"
#include "core/geometry/skin.h"
#include "core/util/diagnostic.h"
#include "core/grow/grow.h"

namespace sylva::python {

// Thrown for a grammar problem; becomes sylva.GrammarError.
struct GrammarFailure : std::runtime_error {
  explicit GrammarFailure(sylva::Diagnostic d);
  sylva::Diagnostic diagnostic;
};

// Thrown for an invalid skeleton document; becomes sylva.SkeletonError.
struct SkeletonFailure : std::runtime_error {
  explicit SkeletonFailure(sylva::Diagnostic e);
  sylva::Diagnostic error;
};

// The Python Grammar: the source text (re-parsed when defines are given, since -D
// overrides apply at parse time) and the grammar parsed without overrides.
struct PyGrammar {
  PyGrammar(std::string grammar_text, std::string grammar_file);  // throws GrammarFailure
  // A grammar already parsed (a vlab object's, read with its folder's files).
  PyGrammar(std::string grammar_text, std::string grammar_file, std::shared_ptr<const lsys::Grammar> grammar)
      : text(std::move(grammar_text)), file(std::move(grammar_file)), parsed(std::move(grammar)) {}
  static PyGrammar from_file(const std::string& path);            // OSError / GrammarFailure

  // The grammar with `defines` applied (the shared parse when there are none). Safe
  // without the GIL.
  std::shared_ptr<const lsys::Grammar> with_defines(const std::map<std::string, double>& defines) const;

  std::string text;
  std::string file;
  bool vlab_object = false;  // `file` is a vlab object folder: parsed through load_grammar (text: the model's)
  std::shared_ptr<const lsys::Grammar> parsed;
};

// None → nullopt; an int (or numpy integer) in [0, 2**64 - 1] → exactly that value.
// bool/float → TypeError; out of range → OverflowError.
std::optional<uint64_t> seed_from_python(const pybind11::object& value);
// None → nullopt; an int >= 0 → its value; negative → ValueError.
std::optional<int64_t> steps_from_python(const pybind11::object& value);
// None → {}; a dict {str: number} → the override map (non-finite values: ValueError).
std::map<std::string, double> defines_from_python(const pybind11::object& value);
// A formatted diagnostic without its final newline (str(e) should not end in one).
std::string chomp(std::string text);
// Raises OSError from a file's Diagnostic (FileNotFoundError etc. by errno, as open() would).
[[noreturn]] void throw_file_error(const Diagnostic& error);
// `os.fspath(path)` as the caller wrote it (kept verbatim: it is recorded in files).
std::string path_string(const std::filesystem::path& path);

// `value` as a T for the argument `name`: a TypeError that names the argument, what it
// expects and the type it got, never pybind11's "Unable to cast Python instance to C++
// type" (issue 32).
template <class T>
T cast_argument(const pybind11::handle& value, const std::string& name, const char* expected) {
  try {
    return value.cast<T>();
  } catch (const pybind11::cast_error&) {
    throw pybind11::type_error(name + " must be " + expected + ", got " +
                         std::string(pybind11::str(pybind11::type::handle_of(value).attr("__name__"))));
  }
}

// "smooth" or "paper" → its SkinStyle; anything else → ValueError naming `skin`.
SkinStyle skin_style_argument(const std::string& skin);

// Adds everything to the module (sylva_module.cpp) and sylva.render (python_render.cpp).
void bind_module(pybind11::module_& m);
void bind_render(pybind11::module_& m);

}  // namespace sylva::python

namespace pybind11::detail {

// An object made by `Skeleton.__new__(Skeleton)` (or Grammar's) without __init__ holds no
// C++ value: pybind11 would hand every method a fresh block of uninitialised memory
// (to_json, grow: a crash; positions: a shape read from garbage). Every method and
// property takes its object through these casters, which raise TypeError for it instead.
// (Constructors and pickle's __setstate__ take the bare instance, not through them, so
// they still fill such an object.)
template <typename T>
struct initialised_caster : type_caster_base<T> {
  bool load(handle src, bool convert) {
    if (isinstance<T>(src)) {
      auto* inst = reinterpret_cast<instance*>(src.ptr());
      if (!inst->get_value_and_holder(get_type_info(typeid(T))).holder_constructed())
        throw type_error(std::string(Py_TYPE(src.ptr())->tp_name) +
                         " object was made by __new__ without __init__ and holds nothing: make one with "
                         "sylva.Grammar(...), Grammar.from_file(), Grammar.grow(), Skeleton.from_file() or "
                         "Skeleton.from_json()");
    }
    return type_caster_base<T>::load(src, convert);
  }
};
template <>
class type_caster<sylva::Skeleton> : public initialised_caster<sylva::Skeleton> {};
template <>
class type_caster<sylva::python::PyGrammar> : public initialised_caster<sylva::python::PyGrammar> {};

}  // namespace pybind11::detail
