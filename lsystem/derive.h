// derive.h — parallel rewriting of a word by a compiled grammar (docs/spec/grammar.md).
//
// derive() applies the grammar's productions `steps` times to the axiom. Every module is
// rewritten in parallel using the word before the step as context; a module with no
// applicable production is copied unchanged. Cut (%) removes the rest of its branch
// after each step. The interpretation (homomorphism) productions are applied separately
// by interpret(), producing the word the turtle reads without changing the derived word.
//
// Stable random streams: each module carries a 64-bit lineage key. Axiom modules are keyed
// by position; a module produced at successor position j of a production applied to a
// module with key K gets key mix(K, j + 1); a module copied unchanged keeps its key. All
// draws for one module at one step (stochastic choice, rand/uniform/gauss in conditions
// and arguments) come from a stream seeded by (seed, key, step). So editing a rule or a
// #define that changes one branch leaves every other branch's random numbers — and so its
// geometry — bit-identical. Keys are stored only when the grammar draws random numbers.
//
// Errors (Diagnostic): division by zero, NaN/infinity, negative probabilities and
// parameter-count mismatches name the production and the module; a word that would
// exceed max_modules stops the derivation before the memory is taken.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "core/util/progress.h"
#include "lsystem/grammar.h"

namespace sylva::lsys {

struct DeriveOptions {
  std::optional<int64_t> steps;     // overrides `derivation length:`
  std::optional<uint64_t> seed;     // overrides `seed:`
  uint64_t max_modules = 50'000'000;
  // Called with the word after the axiom (step 0) and after every step; returning false
  // stops the derivation, which then fails with the message "cancelled at step N" (a
  // Diagnostic with `cancelled` set). Lets a front end keep each step's word.
  std::function<bool(int64_t step, const Word& word)> on_step;
  // Checked, and told the fraction done, after every step and every 64 Ki modules
  // rewritten within one (core/util/progress.h); cancelled: cancelled_diagnostic().
  Progress progress = {};
};

struct DeriveStats {
  int64_t steps = 0;           // steps performed
  uint64_t modules = 0;        // modules in the result
  uint64_t peak_bytes = 0;     // most bytes held by word buffers at any one time
  // Context pattern modules compared over all steps: the context walk passes over ignored
  // modules and whole branches in one step each, so this is at most the modules tried
  // times their patterns' length (a work counter for tests; docs/limits.md "Work").
  uint64_t context_steps = 0;
  double seconds = 0;
};

// Derives the grammar's word. `stats` (optional) receives counts and the time taken.
Expected<Word> derive(const Grammar& grammar, const DeriveOptions& options = {},
                      DeriveStats* stats = nullptr);

// The same derivation one step at a time, so that a caller can act between steps: grow
// several plants in lockstep and answer their light queries after each step, writing the
// answers into the word's parameters (docs/spec/light.md). derive() is start(), advance()
// until done(), finish(). `grammar` and `options` must outlive it. After a call that
// fails, only destruction is allowed.
class Derivation {
 public:
  Derivation(const Grammar& grammar, const DeriveOptions& options);
  ~Derivation();
  Derivation(const Derivation&) = delete;
  Derivation& operator=(const Derivation&) = delete;

  // The Start block and the axiom (step 0; on_step(0) is called). Once, first.
  Status start();
  // One step: StartEach, the rewriting, the cut, EndEach, on_step. Only while !done().
  Status advance();
  int64_t step() const;   // steps done
  int64_t steps() const;  // the derivation length
  bool done() const { return step() >= steps(); }
  // The current word. A caller may overwrite its parameters between steps.
  Word& word();
  // The End block; the word, with the globals the derivation left. Once, last.
  Expected<Word> finish(DeriveStats* stats = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct InterpretStats {
  int depth = 0;                 // homomorphism passes performed
  uint64_t still_expandable = 0; // modules left unexpanded at the depth limit that a production
                                 //   of their arity could rewrite (Grammar::depth_warnings)
  // Modules written: to the result and, without context, to the pending stack of the
  // depth-first expansion (a work counter for tests; docs/limits.md "Work"). At most
  // 16 x max_modules: beyond that interpretation fails naming its budget.
  uint64_t work = 0;
};

// Applies the homomorphism (interpretation) productions recursively, up to the grammar's
// maximum depth, giving the word the turtle reads. Without context its work is the size of
// the expansion (a module without a production costs once, not once per pass); with
// context each pass reads the whole word of the pass before. Returns a copy of `word` when the
// grammar has no homomorphism.
Expected<Word> interpret(const Grammar& grammar, const Word& word, const DeriveOptions& options = {},
                         InterpretStats* stats = nullptr);

}  // namespace sylva::lsys
