// bench_lsystem_scaling.cpp — see bench_lsystem_scaling.h.
#include "app/bench/bench_lsystem_scaling.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <iostream>
#include <string>

#include "core/grow/grow.h"

namespace sylva::cli {

namespace {

// `count` declared names N0, N1, ... on `module:` lines of 100 names each.
std::string declared_names(int64_t count) {
  std::string text;
  for (int64_t i = 0; i < count; ++i) text += (i % 100 == 0 ? "\nmodule:" : "") + std::string(" N") + std::to_string(i);
  return text + "\n";
}

lsys::Grammar parse_or_exit(const std::string& text) {
  auto g = lsys::parse_grammar(text, "scaling.lsys");
  if (!g) {
    std::cerr << g.error().format();
    std::exit(1);  // a bug in the benchmark's own grammar, not an input error
  }
  return std::move(*g);
}

// Items per second beside the row's time: flat across a family when the work is linear.
void per_item(benchmark::State& state, int64_t items) {
  state.SetComplexityN(items);
  state.counters["items/s"] = benchmark::Counter(static_cast<double>(items), benchmark::Counter::kIsIterationInvariantRate);
}

void declare(benchmark::State& state) {
  const std::string text = declared_names(state.range(0)) + "axiom: N0\n";
  for (auto _ : state) benchmark::DoNotOptimize(lsys::parse_grammar(text, "scaling.lsys").ok());
  per_item(state, state.range(0));
}

void print(benchmark::State& state) {
  // Every other module is "N", a prefix of every declared name: each needs the look-ahead.
  lsys::Grammar g = parse_or_exit(declared_names(state.range(0)) + "axiom: N\n");
  lsys::Word w;
  for (int i = 0; i < 100000; ++i) w.modules.push_back(lsys::Module{g.symbols.intern(i % 2 ? "N" : "N1"), 0, 0});
  for (auto _ : state) benchmark::DoNotOptimize(lsys::print_word(w, g.symbols).size());
  per_item(state, state.range(0));
}

void right_context(benchmark::State& state) {
  const lsys::Grammar g = parse_or_exit("axiom: [" + std::string(state.range(0), 'A') + "]B\nA > ]B -> C\n");
  for (auto _ : state) benchmark::DoNotOptimize(lsys::derive(g)->size());
  per_item(state, state.range(0));
}

void interpret_depth(benchmark::State& state) {
  const lsys::Grammar g =
      parse_or_exit("axiom: " + std::string(state.range(0), 'F') + "A\nhomomorphism:\nA -> A\n");
  const lsys::Word w = *lsys::derive(g);
  for (auto _ : state) benchmark::DoNotOptimize(lsys::interpret(g, w)->size());
  per_item(state, state.range(0));
}

}  // namespace

void register_lsystem_scaling_benchmarks(bool quick) {
  const int64_t n = quick ? 1000 : 10000;
  const struct {
    const char* name;
    void (*run)(benchmark::State&);
  } rows[] = {{"scaling/declare_names", declare},
              {"scaling/print_with_names", print},
              {"scaling/right_context_past_branch", right_context},
              {"scaling/interpret_depth16", interpret_depth}};
  for (const auto& r : rows)
    benchmark::RegisterBenchmark(r.name, r.run)
        ->Arg(n)
        ->Arg(2 * n)
        ->Arg(4 * n)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Complexity();
}

}  // namespace sylva::cli
