// grow.h — the grow stage's entry: a grammar grown into a skeleton (derivation,
// interpretation, the turtle) and a scene's plants grown from their grammars. core/grow/
// is the one room of core/ that reads grammars (lsystem/); everything after it takes
// skeletons. Front ends include this header for the grammar, its derivation and growth.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/geometry/skeleton.h"
#include "core/grow/turtle.h"
#include "core/scene/scene.h"
#include "core/util/diagnostic.h"
#include "core/util/progress.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva {

// Everything `sylva grow` does: derive, interpret, build the skeleton, record the source.
struct GrowResult {
  Skeleton skeleton;
  uint64_t modules = 0;  // modules in the derived word
  lsys::DeriveStats derive;
  lsys::InterpretStats interpret;
  TurtleStats turtle;
  double seconds = 0;    // total
};

// Grows `grammar` (already parsed with its define overrides). `grammar_path` and
// `defines` are recorded in skeleton.source; seed and steps come from options or the
// grammar. options.progress covers the whole: derivation, interpretation and turtle as
// its parts ("derive", "interpret", "turtle"); cancelled: cancelled_diagnostic().
Expected<GrowResult> grow(const lsys::Grammar& grammar, const lsys::DeriveOptions& options,
                                const std::string& grammar_path,
                                const std::map<std::string, double>& defines);

// Grows every plant of `scene` that has no skeleton yet from its grammar (with its seed,
// steps and defines) and stores the skeleton in the plant, untransformed. The first
// error, for an error with a place in the grammar, is the grammar's own Diagnostic (its
// file, line, column and source line) with a note at the scene key that named the grammar
// (scene.file at plants[i].grammar_loc: "plants[i].grammar names this grammar"); for one
// without (an unreadable grammar, a define it lacks) the error is at that key with the
// grammar's as a note; a path not ending in .lsys is never quoted (docs/design.md). Progress: one equal share per plant to grow;
// cancelled: cancelled_diagnostic(), the plants grown so far keep their skeletons.
Status grow_scene_plants(Scene& scene, uint64_t max_modules = 50'000'000, const Progress& progress = {});

}  // namespace sylva
