// vlab_object.h — vlab objects and cpfg view files (docs/spec/grammar.md "cpfg model files and
// vlab objects", docs/cpfg.md "vlab objects").
//
// A vlab object is a folder whose `specifications` file holds, among its menu commands, the
// cpfg command line that generates the model: `cpfg [options] model.l view.v [anim.a]`.
// load_grammar() (grammar.h) takes such a folder wherever it takes a grammar file: it reads
// the model with the cpfg reader, then the view file's turtle commands (CPFG manual 8.1.1,
// 8.1.5, 8.1.8) into the grammar's turtle defaults. What only changes cpfg's window
// (projection, lights, fonts, window options) is read and ignored; what would change the
// plant and sylva cannot do yet is an error at its place naming the feature.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"
#include "lsystem/grammar.h"

namespace sylva::lsys {

// Reads the vlab object in `folder`. Errors: no `specifications`, no cpfg command in it, an
// option sylva cannot follow (an environmental program, -e), a missing model or view file,
// and every error of the model and the view file, each at its place.
Expected<Grammar> load_vlab_object(const std::string& folder, const ParseOptions& options = {});

// The model file (its path) the object's `specifications` cpfg command names: what an
// editor edits. Errors as load_vlab_object's for the specifications.
Expected<std::string> vlab_model_file(const std::string& folder);

// The vlab object in `folder` with its model's text given (an editor's copy, not the file):
// read as load_vlab_object reads it, the view file, functions, environment and colours
// included; messages name the model file.
Expected<Grammar> parse_vlab_object(const std::string& folder, const std::string& model_text,
                                    const ParseOptions& options = {});

// A slider of a vlab panel (`panel.l`, vlab's panel manager): `type: SLIDER` with `name:`,
// `min/max: lo hi`, `value: v` and `message: d NAME %d scale`, which vlab's parameter
// editor turns into `#define NAME v / scale`. So the define's range is lo / scale to
// hi / scale in steps of 1 / scale. Other items (labels, buttons, menus) and sliders with
// another message are left out; nothing here is an error (a panel only helps).
struct PanelSlider {
  std::string label;   // the slider's name in the panel
  std::string define;  // the #define it sets
  double min = 0, max = 1, step = 1, value = 0;
};
std::vector<PanelSlider> read_panel_sliders(std::string_view text);

// Applies the turtle commands of the cpfg view file at `path` to `grammar`.
Status apply_view_file(const std::string& path, Grammar& grammar);

}  // namespace sylva::lsys
