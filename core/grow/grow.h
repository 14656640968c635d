// grow.h — the grow stage's entry: a grammar grown into a skeleton (derivation,
// interpretation, the turtle) and a scene's plants grown from their grammars. core/grow/
// is the one room of core/ that reads grammars (lsystem/); everything after it takes
// skeletons. Front ends include this header for the grammar, its derivation and growth.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/grow/turtle.h"
#include "core/scene/light_queries.h"
#include "core/scene/scene.h"
#include "core/util/diagnostic.h"
#include "core/util/progress.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/vlab_object.h"  // vlab objects for the front ends (the studio opens one)

namespace sylva {

// What answering a grammar's light queries cost while it grew (docs/spec/light.md).
struct LightGrowthStats {
  uint64_t answers = 0;     // times the queries were answered (steps with queries)
  uint64_t queries = 0;     // queries answered, over all answers
  uint64_t photons = 0;     // traced, over all answers
  double seconds = 0;       // wall time of the answers: interpretation, turtle, tracing
  double cpu_seconds = 0;   // CPU time of the tracing
  double mean_relative_error = 0;  // of the last answer (LightAnswerStats)
};

// The light a grammar's `?E` queries are answered in. A grammar with queries and no oracle
// is an error; a grammar without queries never calls the oracle.
struct GrowLight {
  const LightOracle* oracle = nullptr;
  // The light's scene: its sun, ground and environment, and its plants: those with
  // skeletons shade the growing plant, those without grow beside it in lockstep from their
  // grammars (their errors placed at the scene's keys). The grammar grows at the scene's
  // origin. Null: the default scene's light (scene.md: the sun from (0.5, 1, 0.3)) over
  // the ground y = 0, no other plant.
  const Scene* scene = nullptr;
};

// Whether any module the grammar writes (axiom, productions, decomposition, homomorphism) is a light
// query: only then does growing it trace light.
bool grammar_queries_light(const lsys::Grammar& grammar);
// Whether it writes a turtle query (?P, ?H, ?L or ?U; CPFG manual 6.9): then every step's
// word is interpreted and drawn by the turtle, which fills them (no light is traced).
bool grammar_queries_turtle(const lsys::Grammar& grammar);

// A light query of the grown word and its last answer (light.md), in the plant's frame.
struct GrowQuery {
  glm::dvec3 position{0, 0, 0};  // where the turtle stood at the ?E, metres
  double q = 0;                  // its first parameter: the last answer (or the grammar's value)
  glm::dvec3 toward{0, 0, 0};    // its direction parameters ((0, 0, 0) for ?E(q))
};

// The ?E modules of the derived `word`, in word order, each paired with the position the
// turtle recorded for it (`positions`, in the order the turtle met them: build_skeleton's
// queries); the first min(queries, positions) of them.
std::vector<GrowQuery> word_queries(const lsys::Word& word, std::span<const glm::dvec3> positions);

// Everything `sylva grow` does: derive, interpret, build the skeleton, record the source.
struct GrowResult {
  Skeleton skeleton;
  uint64_t modules = 0;  // modules in the derived word
  lsys::DeriveStats derive;
  lsys::InterpretStats interpret;
  TurtleStats turtle;
  LightGrowthStats light;  // zero without light queries
  std::vector<GrowQuery> queries;  // the word's ?E modules in word order (none without)
  double seconds = 0;    // total
};

// Grows `grammar` (already parsed with its define overrides). `grammar_path` and
// `defines` are recorded in skeleton.source; seed and steps come from options or the
// grammar. options.progress covers the whole: derivation, interpretation and turtle as
// its parts ("derive", "interpret", "turtle"); cancelled: cancelled_diagnostic().
// A grammar with light queries grows at the origin of light.scene (light.md): after the
// axiom and after every `every`-th step the word is interpreted and every `?E` answered.
Expected<GrowResult> grow(const lsys::Grammar& grammar, const lsys::DeriveOptions& options,
                                const std::string& grammar_path,
                                const std::map<std::string, double>& defines, const GrowLight& light = {});

// The derived word of `grammar`: lsys::derive(), or for a grammar with light queries the
// derivation grow() runs in `light` (the word's queries hold the last answers).
Expected<lsys::Word> derive_word(const lsys::Grammar& grammar, const lsys::DeriveOptions& options,
                                 const GrowLight& light = {}, LightGrowthStats* stats = nullptr,
                                 lsys::DeriveStats* derive_stats = nullptr);

// A vlab object's colours (lsys::Grammar::colours, docs/cpfg.md "Colours") as scene
// materials: each colour index the table does not name yet gets the colour (as a linear
// albedo) and the specular weight. Indices from kMaterialSlots on are left out (the renderers'
// table ends there). Nothing for a grammar without colours.
void add_grammar_colours(const std::vector<lsys::Grammar::Colour>& colours, std::map<uint32_t, SceneMaterial>& table);

// Grows every plant of `scene` that has no skeleton yet from its grammar (with its seed,
// steps and defines) and stores the skeleton in the plant, untransformed. The first
// error, for an error with a place in the grammar, is the grammar's own Diagnostic (its
// file, line, column and source line) with a note at the scene key that named the grammar
// (scene.file at plants[i].grammar_loc: "plants[i].grammar names this grammar"); for one
// without (an unreadable grammar, a define it lacks) the error is at that key with the
// grammar's as a note; a path not ending in .lsys is never quoted (docs/design.md). Progress: one equal share per plant to grow;
// cancelled: cancelled_diagnostic(), the plants grown so far keep their skeletons.
// The plants' vlab colour maps fill the materials the scene's table leaves unnamed, the
// first plant's first (add_grammar_colours).
// When any plant to grow queries light (`?E`), every plant to grow grows in lockstep in
// the scene's light (light.md): step k of each is interpreted before step k's queries
// are answered, so neighbours shade each other; plants that already have skeletons shade
// them too. `light` answers the queries (null with queries: an error).
// `until_step` (a growth animation's frame, docs/animation.md): every plant grows
// min(until_step, its derivation length) steps — the scene as it stood at that step of
// its growth, identical to the whole growth's words at that step, light included.
Status grow_scene_plants(Scene& scene, uint64_t max_modules = 50'000'000, const Progress& progress = {},
                         const LightOracle* light = nullptr, std::optional<int64_t> until_step = std::nullopt);

// The derivation length of the scene's longest-growing plant (its `steps` key, else its
// grammar's `derivation length:`) after grow_scene_plants: the last frame of its growth
// animation; 0 when no plant grew from a grammar.
int64_t scene_growth_length(const Scene& scene);

}  // namespace sylva
