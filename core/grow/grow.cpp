// grow.cpp — growing a grammar into a skeleton, and a scene's plants from their grammars
// (each distinct recipe once, on all cores).
#include "core/grow/grow.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "core/util/parallel.h"

namespace sylva {

Expected<GrowResult> grow(const lsys::Grammar& g, const lsys::DeriveOptions& options,
                                const std::string& grammar_path, const std::map<std::string, double>& defines) {
  auto t0 = std::chrono::steady_clock::now();
  GrowResult r;
  // Shares of the whole for the progress bar: the derivation's last step usually
  // dominates, the turtle reads every module once.
  const bool interprets = !g.homomorphism.empty();
  const double derive_end = interprets ? 0.6 : 0.7, interpret_end = 0.7;
  lsys::DeriveOptions part = options;
  part.progress = options.progress.part(0, derive_end);
  auto word = lsys::derive(g, part, &r.derive);
  if (!word) return word.error();
  r.modules = word->size();
  const lsys::Word* turtle_word = &*word;
  Expected<lsys::Word> interpreted = lsys::Word{};
  if (interprets) {
    part.progress = options.progress.part(derive_end, interpret_end);
    interpreted = lsys::interpret(g, *word, part, &r.interpret);
    if (!interpreted) return interpreted.error();
    turtle_word = &*interpreted;
  }
  auto sk = build_skeleton(*turtle_word, g, &r.turtle, options.progress.part(interpret_end, 1));
  if (!sk) return sk.error();
  r.skeleton = std::move(*sk);
  r.skeleton.source.grammar = grammar_path;
  r.skeleton.source.seed = options.seed.value_or(g.seed);
  r.skeleton.source.steps = options.steps.value_or(g.steps);
  r.skeleton.source.defines = defines;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

// Whether a scene's grammar path names a grammar: `.lsys` (docs/spec/scene.md), a cpfg `.l`
// or a vlab object (docs/cpfg.md).
bool looks_like_grammar(const std::string& path) { return lsys::is_grammar_path(path); }

}  // namespace

Status grow_scene_plants(Scene& scene, uint64_t max_modules, const Progress& progress) {
  // Where the scene names plant i's grammar: its own entry or its scatter entry.
  auto named_by = [&](size_t i) {
    const ScenePlant& p = scene.plants[i];
    return p.scatter ? "scatter[" + std::to_string(p.scatter - 1) + "]" : "plants[" + std::to_string(i) + "]";
  };
  // Each (grammar, defines) is parsed once; a parsed grammar is only read by derive.
  using Source = std::pair<std::string, std::map<std::string, double>>;
  std::map<Source, Expected<lsys::Grammar>> grammars;
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const ScenePlant& p = scene.plants[i];
    if (p.skeleton) continue;
    Source key{p.grammar, p.defines};
    if (grammars.count(key)) continue;
    if (progress.cancelled()) return cancelled_diagnostic();
    lsys::ParseOptions parse;
    parse.define_overrides = p.defines;
    grammars.emplace(std::move(key), lsys::load_grammar(p.grammar, parse));
  }
  // A grammar that draws no random number (no stochastic production, no rand, uniform or
  // gauss, no random axiom) grows the same shape from every seed: its plants' seed is left
  // out of the recipe, and each plant's copy gets its own seed back in its source.
  auto seed_matters = [&](const ScenePlant& p) {
    const Expected<lsys::Grammar>& g = grammars.at(Source{p.grammar, p.defines});
    return !g || g->uses_random || g->axiom_successor.has_value();
  };
  // The distinct recipes (grammar, defines, seed, steps) among the plants to grow, each
  // derived once — a scatter entry's instances share a few — in plant order, so the first
  // failing plant is the one reported whatever the threads do.
  using Recipe = std::tuple<std::string, std::map<std::string, double>, std::optional<uint64_t>, std::optional<int64_t>>;
  std::map<Recipe, size_t> recipe_of;
  std::vector<size_t> first_plant;    // per recipe: the first plant that asks for it
  std::vector<size_t> plant_recipe(scene.plants.size(), SIZE_MAX);
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const ScenePlant& p = scene.plants[i];
    if (p.skeleton) continue;
    const std::optional<uint64_t> seed = seed_matters(p) ? p.seed : std::nullopt;
    auto [it, added] = recipe_of.try_emplace(Recipe{p.grammar, p.defines, seed, p.steps}, first_plant.size());
    if (added) first_plant.push_back(i);
    plant_recipe[i] = it->second;
  }
  std::vector<std::optional<Expected<GrowResult>>> grown(first_plant.size());
  std::atomic<size_t> done{0};
  std::mutex report;
  const double total = static_cast<double>(std::max<size_t>(1, first_plant.size()));
  parallel_for(first_plant.size(), 0, progress.cancel_flag(), [&](size_t r, unsigned) {
    const ScenePlant& p = scene.plants[first_plant[r]];
    const Expected<lsys::Grammar>& g = grammars.at(Source{p.grammar, p.defines});
    if (!g) return;  // reported below, at its first plant
    lsys::DeriveOptions derive;
    derive.steps = p.steps;
    derive.seed = p.seed;
    derive.max_modules = max_modules;
    // One plant: its derivation's own progress; many: each polls the flag, reports once done.
    derive.progress = first_plant.size() == 1 ? progress : Progress(progress.cancel_flag());
    grown[r] = grow(*g, derive, p.grammar, p.defines);
    const size_t finished = done.fetch_add(1) + 1;
    if (first_plant.size() > 1) {
      std::lock_guard<std::mutex> lock(report);
      progress.report(static_cast<double>(finished) / total, "grow");
    }
  });
  // Every plant whose recipe grew keeps its skeleton, also when another failed or the
  // work was cancelled.
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const size_t r = plant_recipe[i];
    if (r == SIZE_MAX || !grown[r] || !*grown[r]) continue;
    ScenePlant& p = scene.plants[i];
    p.skeleton = (*grown[r])->skeleton;
    // A recipe without its seed: this plant's own, as grow() would have recorded it.
    if (!seed_matters(p)) p.skeleton->source.seed = p.seed.value_or(grammars.at(Source{p.grammar, p.defines})->seed);
  }
  if (progress.cancelled()) return cancelled_diagnostic();
  for (size_t r = 0; r < first_plant.size(); ++r) {
    const size_t i = first_plant[r];
    const ScenePlant& p = scene.plants[i];
    auto located = [&](Diagnostic d) {
      if (d.cancelled) return d;
      // A file that is not a grammar (/etc/passwd, a picture): the error is the scene's key,
      // and nothing of the file is quoted — not its line, not the parser's message, which
      // may name a word of it (docs/limits.md "Inputs").
      if (!looks_like_grammar(p.grammar)) {
        Diagnostic top = diagnostic_at(
            scene.file, p.grammar_loc,
            named_by(i) + ".grammar names '" + p.grammar + "', which is not a grammar (a .lsys file)" +
                (d.loc.line ? ": its line " + std::to_string(d.loc.line) + " is not L-system text"
                            : ": " + d.message));
        top.error_number = d.error_number;
        return top;
      }
      // No place in the grammar (it cannot be read, or the scene's defines name a define
      // it lacks): what to change is the scene's key — the error there, the grammar's as a note.
      if (d.loc.line == 0) {
        std::string what = d.message;
        if (what.starts_with("-D ")) what = "its defines name " + what.substr(3);  // "-D X: the grammar has no …"
        Diagnostic top = diagnostic_at(scene.file, p.grammar_loc, named_by(i) + ".grammar '" + p.grammar + "': " + what);
        top.error_number = d.error_number;
        d.notes.clear();
        return std::move(top).with_note(std::move(d));
      }
      // An error in the grammar: the grammar's own diagnostic, and where the scene named it.
      Diagnostic note = diagnostic_at(scene.file, p.grammar_loc, named_by(i) + ".grammar names this grammar");
      return std::move(d).with_note(std::move(note));
    };
    const Expected<lsys::Grammar>& g = grammars.at(Source{p.grammar, p.defines});
    if (!g) return located(g.error());
    if (!grown[r]) return cancelled_diagnostic();
    if (!*grown[r]) return located(grown[r]->error());
  }
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const ScenePlant& plant = scene.plants[i];
    if (auto problem = plant_extent_problem(*plant.skeleton, plant.position, plant.scale))
      return diagnostic_at(scene.file, plant.grammar_loc, named_by(i) + ": " + *problem);
  }
  progress.report(1, "grow");
  return {};
}

}  // namespace sylva
