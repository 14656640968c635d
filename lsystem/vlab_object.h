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

#include "core/util/diagnostic.h"
#include "lsystem/grammar.h"

namespace sylva::lsys {

// Reads the vlab object in `folder`. Errors: no `specifications`, no cpfg command in it, an
// option sylva cannot follow (an environmental program, -e), a missing model or view file,
// and every error of the model and the view file, each at its place.
Expected<Grammar> load_vlab_object(const std::string& folder, const ParseOptions& options = {});

// Applies the turtle commands of the cpfg view file at `path` to `grammar`.
Status apply_view_file(const std::string& path, Grammar& grammar);

}  // namespace sylva::lsys
