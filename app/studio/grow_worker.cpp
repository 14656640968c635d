// grow_worker.cpp — see grow_worker.h.
#include "app/studio/grow_worker.h"

#include <algorithm>

#include "core/grow/turtle.h"
#include "core/grow/grow.h"
#include "app/front/light.h"

namespace sylva::studio {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The request's text as a grammar: a vlab object's model with its object's files, else the text alone.
Expected<lsys::Grammar> parse(const GrowRequest& r, const lsys::ParseOptions& po) {
  return r.object_folder.empty() ? lsys::parse_grammar(r.text, r.file, po)
                                 : lsys::parse_vlab_object(r.object_folder, r.text, po);
}

}  // namespace

// What plants[0]'s last derivation left: its key and each step's word.
struct GrowWorker::Cache {
  std::string text, file, object_folder;
  std::map<std::string, double> defines;
  std::optional<uint64_t> seed;
  uint64_t max_modules = 0;
  Scene light;  // the words of a grammar with ?E depend on it
  std::shared_ptr<const lsys::Grammar> grammar;
  std::vector<std::optional<lsys::Word>> words;  // by step; nullopt: not kept (budget)
  bool matches(const GrowRequest& r) const {
    return grammar && text == r.text && file == r.file && object_folder == r.object_folder &&
           defines == r.plants[0].defines &&
           seed == r.plants[0].seed && max_modules == r.max_modules &&
           (!grammar_queries_light(*grammar) || (light.sun == r.light.sun && light.ground == r.light.ground &&
                                                  light.environment == r.light.environment));
  }
};

GrowWorker::GrowWorker(uint64_t cache_bytes)
    : cache_(std::make_unique<Cache>()), cache_bytes_(cache_bytes), thread_([this] { run(); }) {}

GrowWorker::~GrowWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
    ++generation_;  // the running request sees itself stale and stops
  }
  wake_.notify_all();
  thread_.join();
}

uint64_t GrowWorker::submit(GrowRequest request) {
  uint64_t gen;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    gen = ++generation_;
    pending_ = std::move(request);
    pending_generation_ = gen;
    pending_submitted_ = Clock::now();
    ++counts_.submitted;
  }
  wake_.notify_one();
  return gen;
}

void GrowWorker::cancel() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++generation_;
    pending_.reset();
  }
  idle_.notify_all();
}

std::optional<GrowOutcome> GrowWorker::poll() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!done_) return std::nullopt;
  std::optional<GrowOutcome> out;
  if (done_->generation == generation_.load()) out = std::move(done_);
  else ++counts_.dropped;
  done_.reset();
  return out;
}

bool GrowWorker::result_waiting() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.has_value();
}

bool GrowWorker::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_ || pending_.has_value();
}

void GrowWorker::progress(int64_t* step, int64_t* steps) const {
  *step = progress_step_.load();
  *steps = progress_steps_.load();
}

WorkerCounts GrowWorker::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

bool GrowWorker::wait_idle(double timeout_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::duration<double>(timeout_s), [this] { return !running_ && !pending_; });
}

void GrowWorker::run() {
  for (;;) {
    GrowRequest request;
    uint64_t gen;
    Clock::time_point submitted;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return quit_ || pending_.has_value(); });
      if (quit_) return;
      request = std::move(*pending_);
      pending_.reset();
      gen = pending_generation_;
      submitted = pending_submitted_;
      running_ = true;
      ++counts_.started;
    }
    bool cancelled = false;
    GrowOutcome outcome = grow(request, gen, &cancelled);
    outcome.submitted = submitted;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_ = false;
      if (cancelled) {
        ++counts_.cancelled;
      } else {
        ++counts_.finished;
        if (done_) ++counts_.dropped;  // an older result nobody polled
        done_ = std::move(outcome);
      }
    }
    idle_.notify_all();
    if (!cancelled && notify_) notify_();
  }
}

GrowOutcome GrowWorker::grow(const GrowRequest& request, uint64_t gen, bool* cancelled) {
  const Clock::time_point start = Clock::now();
  GrowOutcome out;
  out.generation = gen;
  *cancelled = false;
  progress_step_ = 0;
  progress_steps_ = 0;
  auto fail = [&](Diagnostic d) {
    out.error = std::move(d);
    out.worker_seconds = seconds_since(start);
    return out;
  };
  if (request.plants.empty()) return fail(file_diagnostic(request.file, "no plant to grow"));

  // plants[0]: from the cache when the text, defines, seed and limit are the same.
  Cache& cache = *cache_;
  const PlantVariant& first = request.plants[0];
  if (!cache.matches(request)) {
    lsys::ParseOptions po;
    po.define_overrides = first.defines;
    auto parsed = parse(request, po);
    if (!parsed) return fail(parsed.error());
    cache.words.clear();
    cache.grammar = std::make_shared<const lsys::Grammar>(std::move(*parsed));
    cache.text = request.text;
    cache.file = request.file;
    cache.object_folder = request.object_folder;
    cache.defines = first.defines;
    cache.seed = first.seed;
    cache.max_modules = request.max_modules;
    cache.light = request.light;
  }
  const lsys::Grammar& g = *cache.grammar;
  out.defines = g.defines;
  out.colours = g.colours;
  out.grammar_seed = g.seed;
  out.grammar_steps = g.steps;
  out.steps = first.steps.value_or(g.steps);
  out.shown_step = std::clamp<int64_t>(request.show_step.value_or(out.steps), 0, out.steps);
  if (stale(gen)) return *cancelled = true, out;

  lsys::DeriveOptions options;
  options.seed = first.seed;
  options.max_modules = request.max_modules;
  const lsys::Word* word = nullptr;
  std::optional<lsys::Word> derived;
  if (static_cast<int64_t>(cache.words.size()) > out.shown_step && cache.words[out.shown_step]) {
    word = &*cache.words[out.shown_step];
    out.from_cache = true;
  } else {
    // Derive to the shown step, keeping every step's word within the budget.
    cache.words.clear();
    uint64_t kept = 0;
    progress_steps_ = out.shown_step;
    options.steps = out.shown_step;
    options.on_step = [&](int64_t step, const lsys::Word& w) {
      progress_step_ = step;
      if (stale(gen)) return false;
      const uint64_t bytes = w.capacity_bytes();
      if (kept + bytes <= cache_bytes_) {
        cache.words.emplace_back(w);
        kept += bytes;
      } else {
        cache.words.emplace_back(std::nullopt);
      }
      return true;
    };
    auto result = derive_word(g, options, {&cpu_light_oracle(), &request.light}, &out.light);
    options.on_step = nullptr;
    if (stale(gen)) {
      cache.grammar.reset();  // the cache may be incomplete: derive again next time
      return *cancelled = true, out;
    }
    if (!result) {
      cache.grammar.reset();
      return fail(result.error());
    }
    derived = std::move(*result);
    word = &*derived;
  }
  out.modules = word->size();

  // The skeleton of word `w`, its ?E answers appended to out.queries.
  auto build = [&](const lsys::Grammar& grammar, const lsys::Word& w) -> Expected<Skeleton> {
    lsys::InterpretStats istats;
    auto interpreted = lsys::interpret(grammar, w, options, &istats);
    if (!interpreted) return interpreted.error();
    if (istats.still_expandable && out.warning.empty())
      out.warning = request.file + ": warning: the interpretation stopped at maximum depth " +
                    std::to_string(grammar.max_depth) + " with " + std::to_string(istats.still_expandable) +
                    " modules still expandable";
    if (stale(gen)) return Diagnostic{};
    std::vector<glm::dvec3> positions;
    const bool queries = grammar_queries_light(grammar);
    auto sk = build_skeleton(*interpreted, grammar, nullptr, {}, queries ? &positions : nullptr);
    out.queries.push_back(queries ? word_queries(w, positions) : std::vector<GrowQuery>{});
    return sk;
  };
  auto record_source = [&](Skeleton& sk, const PlantVariant& v, uint64_t seed, int64_t steps) {
    sk.source.grammar = request.file;
    sk.source.seed = seed;
    sk.source.steps = steps;
    sk.source.defines = v.defines;
  };
  {
    auto sk = build(g, *word);
    if (stale(gen)) return *cancelled = true, out;
    if (!sk) return fail(sk.error());
    record_source(*sk, first, first.seed.value_or(g.seed), out.shown_step);
    out.segments += sk->segment_count();
    out.leaves += sk->leaves.size();
    out.skeletons.push_back(std::move(*sk));
  }
  // The other plants that grow from this text (a scene): each with its own overrides.
  for (size_t p = 1; p < request.plants.size(); ++p) {
    const PlantVariant& v = request.plants[p];
    lsys::ParseOptions po;
    po.define_overrides = v.defines;
    auto parsed = parse(request, po);
    if (!parsed) return fail(parsed.error());
    lsys::DeriveOptions o;
    o.seed = v.seed;
    o.steps = v.steps;
    o.max_modules = request.max_modules;
    o.on_step = [&](int64_t, const lsys::Word&) { return !stale(gen); };
    auto w = derive_word(*parsed, o, {&cpu_light_oracle(), &request.light});
    if (stale(gen)) return *cancelled = true, out;
    if (!w) return fail(w.error());
    auto sk = build(*parsed, *w);
    if (stale(gen)) return *cancelled = true, out;
    if (!sk) return fail(sk.error());
    record_source(*sk, v, v.seed.value_or(parsed->seed), v.steps.value_or(parsed->steps));
    out.segments += sk->segment_count();
    out.leaves += sk->leaves.size();
    out.skeletons.push_back(std::move(*sk));
  }
  out.worker_seconds = seconds_since(start);
  return out;
}

}  // namespace sylva::studio
