// render_input.h — what `sylva render` and `sylva bench geometry` draw: INPUT (a .lsys
// grammar, .skel.json skeleton, .scene.json scene, or a .glb/.gltf written by `sylva
// export`) made into a Scene whose plants all have their skeletons (docs/spec/scene.md: a bare
// grammar or skeleton is wrapped in the default scene).
#pragma once

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "app/front/args.h"
#include "core/cpu/render_cpu.h"
#include "core/scene/scene.h"

namespace sylva::cli {

// Whether `path` names an input render understands (by its extension).
bool is_render_input(const std::string& path);
bool is_grammar_input(const std::string& path);  // .lsys, a cpfg .l, a vlab object folder

// Loads INPUT (grammar.grammar; -n/--seed/-D/--max-modules apply to a grammar) and grows
// every plant; `width`/`height` override the scene's image size. Appends what it did to
// `passes`. On failure prints the located error to stderr and returns the exit code.
// `progress` reaches the derivation, interpretation and turtle (grow.h): cancelled (render's
// SIGINT), it returns kInterrupted without a message — the caller says what was kept.
// `growth_step` (a scene's growth animation, docs/animation.md): every plant of a scene
// grows min(growth_step, its derivation length) steps.
std::variant<Scene, ExitCode> load_render_input(const GrammarArgs& grammar, std::optional<uint32_t> width,
                                                std::optional<uint32_t> height,
                                                std::vector<RenderPass>& passes, const Progress& progress = {},
                                                std::optional<int64_t> growth_step = std::nullopt);

// The warning for plants of `scene` (loaded from `input`) that grew nothing to draw — no
// segment and no leaf — or none where every plant has something (an empty plant is no
// error, but a picture of bare ground should not pass unremarked):
//   INPUT: warning: the plant has no segments and no leaves: nothing of it is drawn
//   INPUT: warning: 3 of 12 plants have no segments and no leaves (the first: plants[4], cactus.lsys): ...
std::optional<std::string> empty_plants_warning(const Scene& scene, const std::string& input);

}  // namespace sylva::cli
