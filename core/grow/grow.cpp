// grow.cpp — growing a grammar into a skeleton, and a scene's plants from their grammars
// (each distinct recipe once, on all cores).
#include "core/grow/grow.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <cstdlib>
#include <utility>
#include <vector>

#include "core/grow/vlab_enviro.h"
#include "core/util/clock.h"
#include "core/util/color.h"
#include "core/util/parallel.h"
#include "core/util/random.h"

namespace sylva {

namespace {
// Whether the axiom, a production, the decomposition or the homomorphism writes a module
// `pred` accepts.
template <class Pred>
bool grammar_writes(const lsys::Grammar& g, Pred pred) {
  auto in = [&](const lsys::Successor& s) {
    return std::any_of(s.modules.begin(), s.modules.end(), [&](const lsys::SuccessorModule& m) { return pred(m.symbol); });
  };
  if (std::any_of(g.axiom.modules.begin(), g.axiom.modules.end(), [&](const lsys::Module& m) { return pred(m.symbol); }))
    return true;
  for (const auto* list : {&g.productions, &g.decomposition, &g.homomorphism})
    for (const lsys::Production& p : *list)
      if (in(p.successor)) return true;
  return false;
}
}  // namespace

void add_grammar_colours(const std::vector<lsys::Grammar::Colour>& colours, std::map<uint32_t, SceneMaterial>& table) {
  for (const lsys::Grammar::Colour& c : colours) {
    if (c.index >= kMaterialSlots || table.count(c.index)) continue;
    SceneMaterial m;
    m.albedo_rgb = glm::dvec3(srgb_to_linear(c.srgb[0]), srgb_to_linear(c.srgb[1]), srgb_to_linear(c.srgb[2]));
    m.specular = c.specular;
    table.emplace(c.index, std::move(m));
  }
}

bool grammar_queries_light(const lsys::Grammar& g) {
  return grammar_writes(g, [](lsys::SymbolId s) { return s == lsys::kSymLightQuery; });
}

bool grammar_queries_turtle(const lsys::Grammar& g) { return grammar_writes(g, lsys::is_turtle_query); }

std::vector<GrowQuery> word_queries(const lsys::Word& word, std::span<const glm::dvec3> positions) {
  // The answers sit in the derived word's ?E modules, in the order the turtle met them.
  std::vector<GrowQuery> out;
  for (const lsys::Module& m : word.modules) {
    if (m.symbol != lsys::kSymLightQuery || out.size() >= positions.size()) continue;
    const double* p = word.params_of(m);
    GrowQuery gq;
    gq.position = positions[out.size()];
    gq.q = p[0];
    if (m.param_count == 4) gq.toward = {p[1], p[2], p[3]};
    out.push_back(gq);
  }
  return out;
}

namespace {

// The derived word grown into a skeleton: interpretation, turtle, the source recorded.
Status finish_growth(const lsys::Grammar& g, const lsys::Word& word, const lsys::DeriveOptions& options,
                     const std::string& grammar_path, const std::map<std::string, double>& defines, double derive_end,
                     GrowResult& r) {
  const double interpret_end = 0.7;
  r.modules = word.size();
  const lsys::Word* turtle_word = &word;
  Expected<lsys::Word> interpreted = lsys::Word{};
  if (!g.homomorphism.empty()) {
    lsys::DeriveOptions part = options;
    part.progress = options.progress.part(derive_end, interpret_end);
    interpreted = lsys::interpret(g, word, part, &r.interpret);
    if (!interpreted) return interpreted.error();
    turtle_word = &*interpreted;
  }
  std::vector<glm::dvec3> positions;
  const bool queries = grammar_queries_light(g);
  auto sk = build_skeleton(*turtle_word, g, &r.turtle, options.progress.part(interpret_end, 1),
                           queries ? &positions : nullptr);
  if (!sk) return sk.error();
  r.skeleton = std::move(*sk);
  if (queries) r.queries = word_queries(word, positions);
  r.skeleton.source.grammar = grammar_path;
  r.skeleton.source.seed = options.seed.value_or(g.seed);
  r.skeleton.source.steps = options.steps.value_or(g.steps);
  r.skeleton.source.defines = defines;
  return {};
}

// ---- Growing with queries: light (docs/spec/light.md) and the turtle's (CPFG 6.9) ----

// One plant growing step by step: its grammar, its derivation and where it stands.
struct LightJob {
  const lsys::Grammar* grammar = nullptr;
  lsys::DeriveOptions options;
  ScenePlant placement;  // position, rotation and scale (no skeleton)
  std::unique_ptr<lsys::Derivation> derivation;
  bool turtle_queries = false;  // the grammar writes ?P, ?H, ?L or ?U
};

template <class Pred>
size_t count_modules(const lsys::Word& word, Pred pred) {
  return static_cast<size_t>(
      std::count_if(word.modules.begin(), word.modules.end(), [&](const lsys::Module& m) { return pred(m.symbol); }));
}

size_t count_queries(const lsys::Word& word) {
  return count_modules(word, [](lsys::SymbolId s) { return s == lsys::kSymLightQuery; });
}

// The job's current word interpreted and drawn by the turtle, in the plant's frame: the
// positions of its light queries appended to `light` and its turtle queries' answers to
// `turtle` (either may be null), each checked against the derived word's count of them.
Expected<Skeleton> turtle_now(LightJob& job, std::vector<glm::dvec3>* light, std::vector<glm::dvec3>* turtle) {
  const lsys::Grammar& g = *job.grammar;
  const lsys::Word& word = job.derivation->word();
  lsys::DeriveOptions quiet = job.options;
  quiet.progress = Progress(job.options.progress.cancel_flag());
  quiet.on_step = nullptr;
  const lsys::Word* turtle_word = &word;
  Expected<lsys::Word> interpreted = lsys::Word{};
  if (!g.homomorphism.empty()) {
    interpreted = lsys::interpret(g, word, quiet);
    if (!interpreted) return interpreted.error();
    turtle_word = &*interpreted;
  }
  const size_t light_before = light ? light->size() : 0, turtle_before = turtle ? turtle->size() : 0;
  auto sk = build_skeleton(*turtle_word, g, nullptr, quiet.progress, light, turtle);
  if (!sk) return sk.error();
  auto check = [&](const char* what, size_t derived, size_t drawn) -> Status {
    if (derived == drawn) return {};
    return g.error_at({}, std::string("the homomorphism changes the number of ") + what + " queries (" +
                              std::to_string(derived) + " in the derived word, " + std::to_string(drawn) +
                              " drawn); sylva answers them in word order, so it must keep each one (docs/light.md)");
  };
  if (light)
    if (Status s = check("?E", count_queries(word), light->size() - light_before); !s) return s.error();
  if (turtle)
    if (Status s = check("turtle (?P ?H ?L ?U)", count_modules(word, lsys::is_turtle_query),
                         turtle->size() - turtle_before);
        !s)
      return s.error();
  return std::move(*sk);
}

// The job's current word as a skeleton placed in the world, its queries' positions
// appended to `sensors` (world), in word order.
Expected<Skeleton> placed_now(LightJob& job, std::vector<glm::dvec3>& sensors) {
  std::vector<glm::dvec3> local;
  auto sk = turtle_now(job, &local, nullptr);
  if (!sk) return sk.error();
  ScenePlant p = job.placement;
  p.skeleton = std::move(*sk);
  for (const glm::dvec3& q : local) sensors.push_back(place_point(p, q));
  return place_plant(p);
}

// Writes the turtle's answers into the job's ?P, ?H, ?L and ?U (CPFG manual 6.9): x and y,
// or x, y and z, in the plant's frame.
Status fill_turtle_queries(LightJob& job) {
  std::vector<glm::dvec3> answers;
  if (auto sk = turtle_now(job, nullptr, &answers); !sk) return sk.error();
  lsys::Word& word = job.derivation->word();
  size_t next = 0;
  for (const lsys::Module& m : word.modules) {
    if (!lsys::is_turtle_query(m.symbol)) continue;
    const glm::dvec3& a = answers[next++];
    double* p = word.params.data() + m.param_begin;
    for (uint32_t k = 0; k < m.param_count && k < 3; ++k) p[k] = a[static_cast<int>(k)];
  }
  return {};
}

Diagnostic no_oracle(const lsys::Grammar& g) {
  return g.error_at({}, "this grammar asks for light (?E) but was grown without a light environment (docs/light.md)");
}

struct JobFailure {
  size_t job = 0;
  Diagnostic error;
};

// A position as cpfg writes it to an environmental program through files or pipes: each
// coordinate printed with its conversion and read back (docs/cpfg.md).
glm::dvec3 as_sent(const glm::dvec3& p, const std::vector<std::string>& formats) {
  if (formats.size() != 3) return p;
  glm::dvec3 out;
  for (int k = 0; k < 3; ++k) {
    const double v = p[k];
    const std::string text = lsys::apply_format(formats[static_cast<size_t>(k)], &v);
    out[k] = std::strtod(text.c_str(), nullptr);
  }
  return out;
}

// A vlab object's built-in environmental program (vlab_enviro.h) answers the ?E queries of
// the job's word where the turtle meets them (positions in the plant's frame, rounded as
// cpfg sends them): honda81 each ?E(vigor[, index]), chiba each ?E(r) and ?E(r, x, y, z) (the
// light reaching a ball of radius r there, and with four parameters the brightest
// direction); a query the program does not read is left as it is.
Status answer_environment(LightJob& job) {
  const lsys::Grammar::Environment& env = *job.grammar->environment;
  std::vector<glm::dvec3> positions;
  if (auto sk = turtle_now(job, &positions, nullptr); !sk) return sk.error();
  lsys::Word& word = job.derivation->word();
  std::vector<double*> params;
  std::vector<uint16_t> counts;
  std::vector<glm::dvec3> at;
  size_t next = 0;
  for (const lsys::Module& m : word.modules) {
    if (m.symbol != lsys::kSymLightQuery) continue;
    const glm::dvec3 q = as_sent(positions[next++], env.position_formats);
    // honda81 skips a query without its vigor; chiba one of two or three parameters.
    if (m.param_count == 0 || (env.program == "chiba" && m.param_count > 1 && m.param_count < 4)) continue;
    params.push_back(word.params.data() + m.param_begin);
    counts.push_back(m.param_count);
    at.push_back(q);
  }
  if (env.program == "honda81") {
    std::vector<Honda81Query> queries(at.size());
    for (size_t i = 0; i < at.size(); ++i) queries[i] = {at[i], params[i][0], counts[i] > 1 ? params[i][1] : 0.0};
    const std::vector<double> answers = honda81_answers(env.honda81, queries);
    for (size_t i = 0; i < at.size(); ++i) params[i][0] = answers[i];
    return {};
  }
  std::vector<ChibaBall> balls(at.size());
  for (size_t i = 0; i < at.size(); ++i) balls[i] = {at[i], params[i][0] > 0 ? params[i][0] : env.chiba.radius};
  const std::vector<ChibaAnswer> answers = chiba_answers(env.chiba, balls);
  for (size_t i = 0; i < at.size(); ++i) {
    params[i][0] = answers[i].light;
    if (counts[i] >= 4)
      for (int k = 0; k < 3; ++k) params[i][1 + k] = answers[i].brightest[k];
  }
  return {};
}

// Answers every query of every job's current word at once, writing q (clamped to
// [0, 1]) and the direction into each `?E`'s parameters. Nothing is traced without queries.
// A job whose grammar has a built-in environmental program (a vlab object's) answers its own.
std::optional<JobFailure> answer_queries(std::vector<LightJob>& jobs, std::span<const Skeleton> fixed,
                                         const Scene& scene, const LightOracle* oracle, int64_t step,
                                         LightGrowthStats* stats) {
  size_t total = 0;
  for (size_t k = 0; k < jobs.size(); ++k) {
    LightJob& j = jobs[k];
    if (!j.grammar->environment) {
      total += count_queries(j.derivation->word());
    } else if (count_queries(j.derivation->word()) > 0) {
      if (Status s = answer_environment(j); !s) return JobFailure{k, s.error()};
    }
  }
  if (total == 0) return std::nullopt;
  if (!oracle) return JobFailure{0, no_oracle(*jobs[0].grammar)};
  const Clock::time_point t0 = Clock::now();
  std::vector<Skeleton> plants(fixed.begin(), fixed.end());
  std::vector<glm::dvec3> sensors;
  for (size_t k = 0; k < jobs.size(); ++k) {
    if (jobs[k].grammar->environment) continue;
    auto sk = placed_now(jobs[k], sensors);
    if (!sk) return JobFailure{k, sk.error()};
    plants.push_back(std::move(*sk));
  }
  LightAnswerStats answer_stats;
  auto answers = oracle->answer(plants, sensors, scene, step, &answer_stats);
  if (!answers) return JobFailure{0, answers.error()};
  size_t next = 0;
  for (LightJob& j : jobs) {
    if (j.grammar->environment) continue;
    lsys::Word& word = j.derivation->word();
    for (const lsys::Module& m : word.modules) {
      if (m.symbol != lsys::kSymLightQuery) continue;
      const LightAnswer& a = (*answers)[next++];
      double* p = word.params.data() + m.param_begin;
      p[0] = std::clamp(a.q, 0.0, 1.0);
      if (m.param_count == 4) p[1] = a.toward.x, p[2] = a.toward.y, p[3] = a.toward.z;
    }
  }
  if (stats) {
    ++stats->answers;
    stats->queries += total;
    stats->photons += answer_stats.photons;
    stats->cpu_seconds += answer_stats.cpu_seconds;
    stats->seconds += seconds_since(t0);
    stats->mean_relative_error = answer_stats.mean_relative_error;
  }
  return std::nullopt;
}

// Derives every job in lockstep (light.md). After the axiom and after every step, each
// job that moved on has its turtle queries filled (CPFG manual 6.9); after the axiom and
// after every `every`-th step, all light queries of all jobs are answered at once; then
// each job's on_step sees its word, answers included. On success every derivation is done.
std::optional<JobFailure> derive_stepped(std::vector<LightJob>& jobs, std::span<const Skeleton> fixed,
                                         const Scene& scene, const LightOracle* oracle, LightGrowthStats* stats) {
  const uint32_t every = scene.environment.value_or(LightEnvironment{}).every;
  std::vector<std::function<bool(int64_t, const lsys::Word&)>> on_step(jobs.size());
  for (size_t k = 0; k < jobs.size(); ++k) {
    on_step[k] = std::move(jobs[k].options.on_step);
    jobs[k].options.on_step = nullptr;
    jobs[k].turtle_queries = grammar_queries_turtle(*jobs[k].grammar);
    jobs[k].derivation = std::make_unique<lsys::Derivation>(*jobs[k].grammar, jobs[k].options);
    if (Status s = jobs[k].derivation->start(); !s) return JobFailure{k, s.error()};
  }
  std::vector<char> moved(jobs.size(), 1);
  auto after = [&](int64_t step) -> std::optional<JobFailure> {
    for (size_t k = 0; k < jobs.size(); ++k)
      if (moved[k] && jobs[k].turtle_queries)
        if (Status s = fill_turtle_queries(jobs[k]); !s) return JobFailure{k, s.error()};
    if (step % every == 0)
      if (auto f = answer_queries(jobs, fixed, scene, oracle, step, stats)) return f;
    for (size_t k = 0; k < jobs.size(); ++k)
      if (moved[k] && on_step[k] && !on_step[k](step, jobs[k].derivation->word())) {
        Diagnostic d = jobs[k].grammar->error_at({}, "cancelled at step " + std::to_string(step));
        d.cancelled = true;
        return JobFailure{k, std::move(d)};
      }
    return std::nullopt;
  };
  if (auto f = after(0)) return f;
  for (int64_t step = 1;; ++step) {
    bool advanced = false;
    for (size_t k = 0; k < jobs.size(); ++k) {
      moved[k] = !jobs[k].derivation->done();
      if (!moved[k]) continue;
      if (Status s = jobs[k].derivation->advance(); !s) return JobFailure{k, s.error()};
      advanced = true;
    }
    if (!advanced) return std::nullopt;
    if (auto f = after(step)) return f;
  }
}

// The scene a grammar grows in without one: the default scene's sun over the ground y = 0.
Scene default_light_scene() {
  Scene s;
  s.sun.direction = unit_sun_direction({0.5, 1.0, 0.3});
  s.ground.height = 0;
  return s;
}

// The placed skeletons of a scene's plants that have one (they shade the growing plants).
std::vector<Skeleton> grown_plants(const Scene& scene) {
  std::vector<Skeleton> out;
  for (const ScenePlant& p : scene.plants)
    if (p.skeleton) out.push_back(place_plant(p));
  return out;
}


}  // namespace

namespace {

// Whether a scene's grammar path names a grammar: `.lsys` (docs/spec/scene.md), a cpfg `.l`
// or a vlab object (docs/cpfg.md).
bool looks_like_grammar(const std::string& path) { return lsys::is_grammar_path(path); }

// Plant i's grammar error `d` placed where the scene names the grammar (grow.h).
Diagnostic plant_error(const Scene& scene, size_t i, Diagnostic d) {
  if (d.cancelled) return d;
  const ScenePlant& p = scene.plants[i];
  const std::string named_by =
      p.scatter ? "scatter[" + std::to_string(p.scatter - 1) + "]" : "plants[" + std::to_string(i) + "]";
  // A file that is not a grammar (/etc/passwd, a picture): the error is the scene's key,
  // and nothing of the file is quoted — not its line, not the parser's message, which
  // may name a word of it (docs/limits.md "Inputs").
  if (!looks_like_grammar(p.grammar)) {
    Diagnostic top = diagnostic_at(
        scene.file, p.grammar_loc,
        named_by + ".grammar names '" + p.grammar + "', which is not a grammar (a .lsys file)" +
            (d.loc.line ? ": its line " + std::to_string(d.loc.line) + " is not L-system text" : ": " + d.message));
    top.error_number = d.error_number;
    return top;
  }
  // No place in the grammar (it cannot be read, or the scene's defines name a define
  // it lacks): what to change is the scene's key — the error there, the grammar's as a note.
  if (d.loc.line == 0) {
    std::string what = d.message;
    if (what.starts_with("-D ")) what = "its defines name " + what.substr(3);  // "-D X: the grammar has no …"
    Diagnostic top = diagnostic_at(scene.file, p.grammar_loc, named_by + ".grammar '" + p.grammar + "': " + what);
    top.error_number = d.error_number;
    d.notes.clear();
    return std::move(top).with_note(std::move(d));
  }
  // An error in the grammar: the grammar's own diagnostic, and where the scene named it.
  Diagnostic note = diagnostic_at(scene.file, p.grammar_loc, named_by + ".grammar names this grammar");
  return std::move(d).with_note(std::move(note));
}

// The job that grows scene plant `p` in the light (its grammar `g`, its seed, steps, place).
LightJob job_for_plant(const ScenePlant& p, const lsys::Grammar& g, uint64_t max_modules, const Progress& progress) {
  LightJob job;
  job.grammar = &g;
  job.options.steps = p.steps;
  job.options.seed = p.seed;
  job.options.max_modules = max_modules;
  job.options.progress = Progress(progress.cancel_flag());
  job.placement.position = p.position;
  job.placement.rotate_y_deg = p.rotate_y_deg;
  job.placement.scale = p.scale;
  return job;
}

// The plants first_plant names grown in lockstep in the scene's light (light.md), each
// result in grown[r]; a plant whose grammar did not load is left unset (reported by the
// caller); on a failure the failing plant gets the error and the others are left unset.
template <class Grammars>
void grow_recipes_in_light(const Scene& scene, const Grammars& grammars, const std::vector<size_t>& first_plant,
                           uint64_t max_modules, const Progress& progress, const LightOracle* light,
                           std::vector<std::optional<Expected<GrowResult>>>& grown) {
  std::vector<LightJob> jobs;
  std::vector<size_t> recipe_of_job;
  for (size_t r = 0; r < first_plant.size(); ++r) {
    const ScenePlant& p = scene.plants[first_plant[r]];
    const auto& g = grammars.at({p.grammar, p.defines});
    if (!g) continue;
    if (!light) {
      grown[r] = no_oracle(*g);
      return;
    }
    jobs.push_back(job_for_plant(p, *g, max_modules, progress));
    recipe_of_job.push_back(r);
  }
  if (jobs.empty()) return;
  // The scene's plants that already have skeletons shade the growing ones.
  const std::vector<Skeleton> fixed = grown_plants(scene);
  LightGrowthStats stats;
  if (auto f = derive_stepped(jobs, fixed, scene, light, &stats)) {
    grown[recipe_of_job[f->job]] = std::move(f->error);
    return;
  }
  for (size_t k = 0; k < jobs.size(); ++k) {
    const ScenePlant& p = scene.plants[first_plant[recipe_of_job[k]]];
    GrowResult result;
    result.light = stats;
    auto word = jobs[k].derivation->finish(&result.derive);
    Status s = word ? finish_growth(*jobs[k].grammar, *word, jobs[k].options, p.grammar, p.defines, 0.7, result)
                    : Status(word.error());
    grown[recipe_of_job[k]] = s ? Expected<GrowResult>(std::move(result)) : Expected<GrowResult>(s.error());
    progress.report(static_cast<double>(k + 1) / static_cast<double>(jobs.size()), "grow");
  }
}

}  // namespace

Expected<lsys::Word> derive_word(const lsys::Grammar& g, const lsys::DeriveOptions& options, const GrowLight& light,
                                 LightGrowthStats* stats, lsys::DeriveStats* derive_stats) {
  const bool light_queries = grammar_queries_light(g);
  if (!light_queries && !grammar_queries_turtle(g)) return lsys::derive(g, options, derive_stats);
  if (!light_queries) {
    // Turtle queries only (CPFG manual 6.9): the grammar alone, step by step, no light.
    std::vector<LightJob> jobs(1);
    jobs[0].grammar = &g;
    jobs[0].options = options;
    if (auto f = derive_stepped(jobs, {}, Scene{}, nullptr, stats)) return f->error;
    return jobs[0].derivation->finish(derive_stats);
  }
  if (g.environment && !light.scene) {
    // A vlab object's honda81 or chiba (docs/cpfg.md): its queries answered by that program.
    std::vector<LightJob> jobs(1);
    jobs[0].grammar = &g;
    jobs[0].options = options;
    if (auto f = derive_stepped(jobs, {}, Scene{}, nullptr, stats)) return f->error;
    return jobs[0].derivation->finish(derive_stats);
  }
  if (!light.oracle) return no_oracle(g);
  const Scene scene = light.scene ? *light.scene : default_light_scene();
  const std::vector<Skeleton> fixed = grown_plants(scene);
  std::vector<LightJob> jobs(1);
  jobs[0].grammar = &g;
  jobs[0].options = options;
  // The scene's plants without skeletons grow beside it, in lockstep (light.md).
  std::vector<size_t> plant_of_job = {SIZE_MAX};
  std::vector<std::unique_ptr<const lsys::Grammar>> neighbours;
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const ScenePlant& p = scene.plants[i];
    if (p.skeleton) continue;
    lsys::ParseOptions parse;
    parse.define_overrides = p.defines;
    auto loaded = lsys::load_grammar(p.grammar, parse);
    if (!loaded) return plant_error(scene, i, loaded.error());
    neighbours.push_back(std::make_unique<const lsys::Grammar>(std::move(*loaded)));
    jobs.push_back(job_for_plant(p, *neighbours.back(), options.max_modules, options.progress));
    plant_of_job.push_back(i);
  }
  if (auto f = derive_stepped(jobs, fixed, scene, light.oracle, stats))
    return f->job == 0 ? f->error : plant_error(scene, plant_of_job[f->job], f->error);
  return jobs[0].derivation->finish(derive_stats);
}

Expected<GrowResult> grow(const lsys::Grammar& g, const lsys::DeriveOptions& options,
                                const std::string& grammar_path, const std::map<std::string, double>& defines,
                                const GrowLight& light) {
  auto t0 = std::chrono::steady_clock::now();
  GrowResult r;
  // Shares of the whole for the progress bar: the derivation's last step usually
  // dominates, the turtle reads every module once.
  const double derive_end = !g.homomorphism.empty() ? 0.6 : 0.7;
  lsys::DeriveOptions part = options;
  part.progress = options.progress.part(0, derive_end);
  Expected<lsys::Word> word = derive_word(g, part, light, &r.light, &r.derive);
  if (!word) return word.error();
  if (Status s = finish_growth(g, *word, options, grammar_path, defines, derive_end, r); !s) return s.error();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

Status grow_scene_plants(Scene& scene, uint64_t max_modules, const Progress& progress, const LightOracle* light,
                         std::optional<int64_t> until_step) {
  if (until_step) {
    // The plants as they stood at that step: each one's steps capped, grown, and only the
    // skeletons carried back, so the scene's own keys stay as they were written.
    Scene capped = scene;
    std::map<std::pair<std::string, std::map<std::string, double>>, std::optional<int64_t>> length_of;
    for (ScenePlant& p : capped.plants) {
      if (p.skeleton) continue;
      if (!p.steps) {
        auto [it, added] = length_of.try_emplace({p.grammar, p.defines});
        if (added) {
          lsys::ParseOptions parse;
          parse.define_overrides = p.defines;
          auto g = lsys::load_grammar(p.grammar, parse);
          if (g) it->second = g->steps;  // a grammar that fails is reported below
        }
        p.steps = it->second;
      }
      if (p.steps) p.steps = std::min(*p.steps, *until_step);
    }
    Status grown = grow_scene_plants(capped, max_modules, progress, light);
    for (size_t i = 0; i < scene.plants.size(); ++i)
      if (!scene.plants[i].skeleton && capped.plants[i].skeleton) scene.plants[i].skeleton = std::move(capped.plants[i].skeleton);
    return grown;
  }
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
  for (const ScenePlant& p : scene.plants) {
    if (p.skeleton) continue;
    const Expected<lsys::Grammar>& g = grammars.at(Source{p.grammar, p.defines});
    if (g) add_grammar_colours(g->colours, scene.materials);
  }
  // A grammar that draws no random number (no stochastic production, no rand, uniform or
  // gauss, no random axiom) grows the same shape from every seed: its plants' seed is left
  // out of the recipe, and each plant's copy gets its own seed back in its source.
  auto seed_matters = [&](const ScenePlant& p) {
    const Expected<lsys::Grammar>& g = grammars.at(Source{p.grammar, p.defines});
    return !g || g->uses_random || g->axiom_successor.has_value();
  };
  // Plants that query light grow in lockstep, each its own recipe: each one's light differs.
  bool in_light = false;
  for (const auto& [source, g] : grammars) in_light = in_light || (g && grammar_queries_light(*g));
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
    if (in_light) {
      plant_recipe[i] = first_plant.size();
      first_plant.push_back(i);
      continue;
    }
    const std::optional<uint64_t> seed = seed_matters(p) ? p.seed : std::nullopt;
    auto [it, added] = recipe_of.try_emplace(Recipe{p.grammar, p.defines, seed, p.steps}, first_plant.size());
    if (added) first_plant.push_back(i);
    plant_recipe[i] = it->second;
  }
  std::vector<std::optional<Expected<GrowResult>>> grown(first_plant.size());
  std::atomic<size_t> done{0};
  std::mutex report;
  const double total = static_cast<double>(std::max<size_t>(1, first_plant.size()));
  if (in_light) grow_recipes_in_light(scene, grammars, first_plant, max_modules, progress, light, grown);
  else parallel_for(first_plant.size(), 0, progress.cancel_flag(), [&](size_t r, unsigned) {
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
    auto located = [&](Diagnostic d) { return plant_error(scene, i, std::move(d)); };
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

int64_t scene_growth_length(const Scene& scene) {
  int64_t last = 0;
  for (const ScenePlant& p : scene.plants)
    if (!p.grammar.empty() && p.skeleton) last = std::max(last, p.skeleton->source.steps);
  return last;
}

}  // namespace sylva
