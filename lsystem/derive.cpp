// derive.cpp — the derivation engine (see derive.h for the contract).
//
// Hot loop design: words are flat arrays of 8-byte records; rules are looked up by
// symbol id; a symbol whose first production is context-free, unconditional and
// deterministic with constant arguments is rewritten by copying a prebuilt word (ABOP
// 1.24a runs entirely on this path); bracket partners are precomputed once per step for
// context-sensitive grammars so context search never rescans a branch; nothing recurses
// over the word.
#include "lsystem/derive.h"

#include <algorithm>
#include <optional>
#include <cassert>
#include <chrono>
#include <cmath>
#include <filesystem>

namespace sylva::lsys {

namespace {

constexpr uint64_t kAxiomKeyBase = 0xA7104D5EEDULL;
constexpr uint64_t kHomomorphismStreamBase = 0x40000000ULL;
// Decomposition's streams: step k's pass d draws from base + k·(kMaxDecompositionDepth + 2) + d.
constexpr uint64_t kDecompositionStreamBase = 0xDEC0000000000ULL;
constexpr uint64_t kMaxDecompositionDepth = 1000;  // the parser's limit on maximum depth
constexpr uint64_t kBlockStreamBase = 0xB10C0000ULL;  // + 4 * step + which block
constexpr uint32_t kNoMatch = 0xFFFFFFFFu;
constexpr size_t kMaxParams = 0xFFFFFFF0u;
// Interpretation writes at most this many times --max-modules modules over all its passes
// (docs/limits.md "Work"): the default depth's worth of whole words.
constexpr uint64_t kInterpretBudgetFactor = 16;

struct DeriveFailure {
  SourceLoc loc;
  std::string message;
};

// Thrown out of a rewrite when the Progress is cancelled; derive/interpret return
// cancelled_diagnostic() for it.
struct DeriveCancelled {};

// Cancellation is checked, and progress reported, once per 64 Ki modules rewritten.
constexpr size_t kProgressChunkMask = (size_t{1} << 16) - 1;

std::string module_text(const Word& w, size_t i, const SymbolTable& symbols) {
  Word one;
  const Module& m = w.modules[i];
  one.modules.push_back(Module{m.symbol, m.param_count, 0});
  one.params.assign(w.params_of(m), w.params_of(m) + m.param_count);
  return print_word(one, symbols);
}

// Rewrites one word into another by one set of productions (the grammar's productions
// for a derivation step, or its homomorphism for one interpretation pass).
class Rewriter {
 public:
  Rewriter(const Grammar& g, const std::vector<Production>& productions,
           const std::vector<std::vector<uint32_t>>& by_symbol, uint64_t seed, uint64_t max_modules,
           EvalContext* context)
      : g_(g), productions_(productions), by_symbol_(by_symbol), seed_(seed), max_modules_(max_modules),
        context_(context) {
    uint32_t slots = 0;
    for (const Production& p : productions_) slots = std::max(slots, p.slot_count);
    slots_.assign(slots + 1, 0.0);
    has_rest_of_branch_ = g_.cpfg && g_.symbols.find("=", &rest_of_branch_);
    sub_lsystems_ = g_.has_sub_lsystems() && g_.symbols.find("?", &sub_call_);
    per_lsystem_context_ = sub_lsystems_ && g_.sub_contexts_differ();
    tables_.resize(per_lsystem_context_ ? g_.lsystem_labels.size() : 1);
    uses_tails_ = std::any_of(productions_.begin(), productions_.end(),
                              [](const Production& p) { return !p.predecessor_tail.empty(); });
    direct_.assign(by_symbol_.size(), nullptr);
    for (size_t s = 0; s < by_symbol_.size(); ++s) {
      if (by_symbol_[s].empty()) continue;
      const Production& p = productions_[by_symbol_[s][0]];
      if (!p.has_context() && p.condition.kind == Expr::Kind::kNone && !p.has_statements() &&
          p.probability.kind == Expr::Kind::kNone && p.successor.all_constant && p.predecessor_tail.empty())
        direct_[s] = &p;
    }
    for (const std::vector<uint32_t>& rules : by_symbol_)
      for (uint32_t r : rules) {
        const Production& p = productions_[r];
        uses_context_ |= p.has_context();
        uses_left_context_ |= !p.left_context.empty() && !p.new_left;
        uses_right_context_ |= !p.right_context.empty() && !p.new_right;
        uses_new_left_ |= p.new_left;
        uses_new_right_ |= p.new_right;
      }
  }

  // Rewrites `in` into `out` (empty). `stream` distinguishes steps/passes in the
  // random streams. With `active_in`, only modules flagged there are rewritten (the
  // others are copied) and `active_out` flags the modules produced by a production.
  // `progress` is checked, and told the fraction of `in` rewritten, every 64 Ki modules.
  // `backward` (a backward pass, grammar.h) writes the new word from its end: each module's
  // `>>` context is what the modules to its right have already become.
  void rewrite(const Word& in, Word& out, uint64_t stream, const std::vector<uint8_t>* active_in,
               std::vector<uint8_t>* active_out, const Progress& progress, const char* stage,
               bool backward = false) {
    assert(out.size() == 0);
    if (backward) {
      assert(!active_in && !active_out);
      rewrite_backward(in, out, stream, progress, stage);
      return;
    }
    in_ = &in;
    out_ = &out;
    const bool keyed = !in.lineage.empty();
    enter_word();
    if (uses_context_) compute_brackets(in);
    if (uses_new_left_) {
      new_skip_left_.clear();
      new_open_.clear();
    }
    const size_t n = in.size();
    for (size_t i = 0; i < n; ++i) {
      if ((i & kProgressChunkMask) == 0 && i != 0) {
        if (progress.cancelled()) throw DeriveCancelled{};
        progress.report(static_cast<double>(i) / static_cast<double>(n), stage);
      }
      Rng rng;
      if (uses_tails_) tail_ = TailView{&in, i + 1, 1, n - i - 1, active_in, 0};
      // A recursive pass past this module's L-system's own maximum depth leaves it as it is.
      const bool within = depth_limits_.empty() || pass_depth_ <= depth_limits_[lsystem_];
      const Production* chosen = ((!active_in || (*active_in)[i]) && within) ? select(in, i, stream, rng) : nullptr;
      if (!chosen) {
        copy_module(in, i, out);
        if (active_out) active_out->push_back(0);
        if (sub_lsystems_) track_lsystem(in, i);
      } else {
        apply(*chosen, i, rng, keyed);
        if (active_out) active_out->resize(out.size(), 1);
        if (sub_lsystems_)
          for (size_t k = 0; k <= chosen->predecessor_tail.size(); ++k) track_lsystem(in, i + k);
        i += chosen->predecessor_tail.size();  // a cpfg predecessor's further modules are rewritten too
      }
      if (uses_new_left_) extend_left_tables(out);
    }
  }

  // The production that rewrites module i of `in` (in_), or null: the prebuilt fast path, else
  // choose() with the module's random stream for `stream` (set in `rng`).
  const Production* select(const Word& in, size_t i, uint64_t stream, Rng& rng) {
    const Module& m = in.modules[i];
    if (by_symbol_[m.symbol].empty()) return nullptr;
    const Production* direct = direct_[m.symbol];
    if (direct && direct->predecessor.arity == m.param_count && direct->lsystem == lsystem_) return direct;
    if (!in.lineage.empty()) rng = Rng(mix_pair(mix_pair(seed_, in.lineage[i]), stream));
    return choose(i, m, rng);
  }

  // A backward pass: `in` read from its last module to its first, each module's successor
  // put before what the modules to its right became. The new word is built in `reversed_`
  // (its last module first), so that its context tables grow by appending, then turned round.
  void rewrite_backward(const Word& in, Word& out, uint64_t stream, const Progress& progress, const char* stage) {
    in_ = &in;
    enter_word();  // (a cpfg file has no backward passes: its sub-L-systems are never tracked here)
    Word& rev = reversed_;
    rev.clear();
    out_ = &rev;
    const bool keyed = !in.lineage.empty();
    if (uses_context_) compute_brackets(in);
    new_match_.clear();
    new_open_.clear();
    new_skip_ignored_.clear();
    new_skip_right_.clear();
    new_branch_end_.clear();
    const size_t n = in.size();
    for (size_t done = 0; done < n; ++done) {
      if ((done & kProgressChunkMask) == 0 && done != 0) {
        if (progress.cancelled()) throw DeriveCancelled{};
        progress.report(static_cast<double>(done) / static_cast<double>(n), stage);
      }
      const size_t i = n - 1 - done;
      Rng rng;
      if (uses_tails_) tail_ = TailView{};  // a cpfg predecessor's further modules: cpfg has no backward passes
      const Production* chosen = select(in, i, stream, rng);
      if (!chosen) {
        copy_module(in, i, rev);
      } else {
        successor_.clear();
        out_ = &successor_;
        apply(*chosen, i, rng, keyed);
        out_ = &rev;
        for (size_t k = successor_.size(); k-- > 0;) copy_module(successor_, k, rev);
      }
      if (uses_new_right_) extend_right_tables(rev);
    }
    out_ = &out;
    out.modules.reserve(rev.size());
    out.params.reserve(rev.params.size());
    for (size_t r = rev.size(); r-- > 0;) copy_module(rev, r, out);
  }

  // True if some production of m's symbol takes m's parameter count (only those could apply).
  bool has_rule_of_arity(const Module& m) const {
    for (uint32_t k : by_symbol_[m.symbol])
      if (productions_[k].predecessor.arity == m.param_count && productions_[k].lsystem == lsystem_) return true;
    return false;
  }

  // Interpretation without context (docs/spec/grammar.md "Interpretation rules"), depth first: each
  // module of `in` is expanded completely, its successors in turn up to `max_depth`, before
  // the next one, so a module without a production is copied once rather than once per
  // pass. The result, random streams and lineage keys are those of the passes (pass d
  // rewrites the modules produced by pass d - 1 with stream `stream_base + d`); a pending
  // stack holds at most max_depth successors. Every module written to the stack or `out`
  // counts against `work_budget`.
  void expand(const Word& in, Word& out, uint64_t stream_base, int max_depth, uint64_t work_budget,
              const Progress& progress, int* deepest_applied, uint64_t* left_expandable) {
    out_ = &out;
    const bool keyed = !in.lineage.empty();
    const size_t n = in.size();
    *deepest_applied = 0;
    *left_expandable = 0;
    work_budget_ = work_budget;
    enter_word();
    for (size_t i = 0; i < n; ++i) {
      if ((i & kProgressChunkMask) == 0 && i != 0) {
        if (progress.cancelled()) throw DeriveCancelled{};
        progress.report(static_cast<double>(i) / static_cast<double>(n), "interpret");
      }
      if (by_symbol_[in.modules[i].symbol].empty()) {
        copy_module(in, i, out);  // the common case: nothing to expand, no stack
        if (sub_lsystems_) track_lsystem(in, i);
        continue;
      }
      // The maximum depth of the L-system the module is in (sub-L-systems have their own).
      const int limit = depth_limits_.empty() ? max_depth : depth_limits_[lsystem_];
      stack_.clear();
      stack_depth_.clear();
      copy_module(in, i, stack_);
      stack_depth_.push_back(1);
      size_t consumed = 0;  // modules of `in` after i that a predecessor took with it
      while (!stack_.modules.empty()) {
        const size_t t = stack_.size() - 1;
        const Module m = stack_.modules[t];
        const int d = stack_depth_[t];
        current_depth = d;
        const Production* chosen = nullptr;
        Rng rng;
        const bool has_rules = !by_symbol_[m.symbol].empty();
        if (has_rules && d <= limit) {
          in_ = &stack_;
          // A cpfg predecessor's further modules (CPFG generate.c, ApplyRecursiveProductions):
          // at depth 1 the word's next modules, deeper the rest of the same successor, which
          // lies below t on the stack at the same depth.
          if (uses_tails_)
            tail_ = d == 1 ? TailView{&in, i + 1, 1, n - i - 1, nullptr, 0} : TailView{&stack_, t - 1, -1, t, nullptr, d};
          const Production* direct = direct_[m.symbol];
          if (direct && direct->predecessor.arity == m.param_count && direct->lsystem == lsystem_) {
            chosen = direct;
          } else {
            if (keyed) rng = Rng(mix_pair(mix_pair(seed_, stack_.lineage[t]), stream_base + static_cast<uint64_t>(d)));
            chosen = choose(t, m, rng);
          }
        }
        if (!chosen) {
          if (has_rules && d > limit && g_.depth_warnings && has_rule_of_arity(m)) ++*left_expandable;
          copy_module(stack_, t, out);
          pop(t);
          continue;
        }
        *deepest_applied = std::max(*deepest_applied, d);
        successor_.clear();
        out_ = &successor_;
        apply(*chosen, t, rng, keyed);
        out_ = &out;
        pop(t);
        if (d == 1) consumed = chosen->predecessor_tail.size();
        else for (size_t k = 0; k < chosen->predecessor_tail.size(); ++k) pop(stack_.size() - 1);
        // A failure while pushing names the production, not a module (t is gone).
        current_production = chosen;
        current = SIZE_MAX;
        // Pushed last to first, so the first successor module is expanded next.
        for (size_t k = successor_.size(); k-- > 0;) {
          copy_module(successor_, k, stack_);
          stack_depth_.push_back(d + 1);
        }
      }
      // The module's L-system served its whole expansion; the word's ?( and $ change it after.
      if (sub_lsystems_)
        for (size_t k = 0; k <= consumed; ++k) track_lsystem(in, i + k);
      i += consumed;
    }
  }

  // Pattern modules compared with the word so far (each costs one step of the context
  // walk, however much the walk passes over): the work counter of derive.h's stats.
  uint64_t context_steps() const { return context_steps_; }
  // Modules written (to the result, and by expand() to its stack): interpretation's work.
  uint64_t work() const { return work_; }
  // Starts counting the work of the passes to come against `budget`, naming `what` spends it.
  void set_work_budget(uint64_t budget, const char* what = "the interpretation") {
    work_ = 0;
    work_budget_ = budget;
    budget_what_ = what;
  }
  void set_seed(uint64_t seed) { seed_ = seed; }
  // A cpfg file's maximum depths by L-system (Grammar::SubLsystem), which a recursive
  // application (apply_recursively) holds each module to; empty: its max_depth for all.
  void set_depth_limits(std::vector<int> limits) { depth_limits_ = std::move(limits); }
  // The pass of a recursive application with context that rewrite() performs (from 1).
  void set_pass_depth(int d) { pass_depth_ = d; }
  int deepest_limit(int max_depth) const {
    return depth_limits_.empty() ? max_depth : *std::max_element(depth_limits_.begin(), depth_limits_.end());
  }

  // Index of the module whose production failed, for messages.
  size_t current = 0;
  const Production* current_production = nullptr;
  int current_depth = 0;  // expand(): the pass the failing module belongs to
  // The word `current` indexes (the word being rewritten, or expand()'s pending stack).
  const Word* current_word() const { return in_; }

 private:
  // Removes the last module of expand()'s stack (index t), with its parameters and key.
  void pop(size_t t) {
    stack_.params.resize(stack_.modules[t].param_begin);
    stack_.modules.pop_back();
    if (!stack_.lineage.empty()) stack_.lineage.pop_back();
    stack_depth_.pop_back();
  }

  void copy_module(const Word& in, size_t i, Word& out) {
    const Module& m = in.modules[i];
    if (++work_ > work_budget_) over_budget();
    if (out.modules.size() + out.params.size() + 1 + m.param_count > max_modules_) too_many();
    if (out.params.size() > kMaxParams) too_many_params();
    out.modules.push_back(Module{m.symbol, m.param_count, static_cast<uint32_t>(out.params.size())});
    if (m.param_count) out.params.insert(out.params.end(), in.params.begin() + m.param_begin,
                                         in.params.begin() + m.param_begin + m.param_count);
    if (!in.lineage.empty()) out.lineage.push_back(in.lineage[i]);
  }

  [[noreturn]] void too_many() {
    throw DeriveFailure{{}, "the word exceeds --max-modules (" + std::to_string(max_modules_) +
                                " modules), each parameter counting as a module; raise --max-modules or lower "
                                "the derivation length"};
  }
  [[noreturn]] void over_budget() {
    throw DeriveFailure{{}, std::string(budget_what_) + " exceeds its budget of " + std::to_string(work_budget_) +
                                " modules written (16 x --max-modules); lower `maximum depth:` or raise --max-modules"};
  }
  [[noreturn]] void too_many_params() {
    throw DeriveFailure{{}, "the word holds more than 4 billion parameters"};
  }

  void bind(const PatternModule& pm, const double* p) {
    for (uint16_t k = 0; k < pm.arity; ++k) slots_[pm.first_slot + k] = p[k];
  }

  // The jump tables of old context (compute_brackets) for one set of ignored modules.
  struct ContextTables {
    std::vector<uint32_t> skip_ignored, skip_right, branch_end, skip_left;
  };

  // One pass over the word before a step: bracket partners and the jump tables that let
  // context matching pass over ignored modules, completed branches and the rest of a
  // branch in one step each (ABOP 1.8's walk, without rescanning what it skips). So the
  // context of a module costs its pattern's length, not the length of what lies between.
  void compute_brackets(const Word& w) {
    const size_t n = w.size();
    match_.assign(n, kNoMatch);
    open_.clear();
    for (size_t i = 0; i < n; ++i) {
      SymbolId s = w.modules[i].symbol;
      if (s == kSymPush) {
        open_.push_back(static_cast<uint32_t>(i));
      } else if (s == kSymPop && !open_.empty()) {
        match_[open_.back()] = static_cast<uint32_t>(i);
        match_[i] = open_.back();
        open_.pop_back();
      }
    }
    // Going right (from the end): the first module at or after j that is not ignored;
    // the same passing over completed branches too (an unclosed '[' stops it); the
    // ']' that ends the branch j is in (n: the word's end; kNoMatch: an unclosed '['
    // lies in the way).
    // One set of jump tables per L-system when a sub-L-system passes over other modules
    // (Grammar::SubLsystem): context is matched with the tables of the L-system whose
    // production it is.
    for (uint32_t k = 0; k < tables_.size(); ++k) {
      const std::vector<uint8_t>& ignored = g_.ignored_in(k);
      if (uses_right_context_) compute_right_tables(w, ignored, tables_[k]);
      if (uses_left_context_) compute_left_table(w, ignored, tables_[k]);
    }
  }

  void compute_right_tables(const Word& w, const std::vector<uint8_t>& ignored, ContextTables& t) {
    const size_t n = w.size();
    std::vector<uint32_t> &skip_ignored = t.skip_ignored, &skip_right = t.skip_right, &branch_end = t.branch_end;
    skip_ignored.assign(n + 1, static_cast<uint32_t>(n));
    skip_right.assign(n + 1, static_cast<uint32_t>(n));
    branch_end.assign(n + 1, static_cast<uint32_t>(n));
    for (size_t j = n; j-- > 0;) {
      const SymbolId s = w.modules[j].symbol;
      const uint32_t after = static_cast<uint32_t>(j + 1);
      skip_ignored[j] = ignored[s] ? skip_ignored[after] : static_cast<uint32_t>(j);
      if (ignored[s]) {
        skip_right[j] = skip_right[after];
        branch_end[j] = branch_end[after];
      } else if (s == kSymPush && match_[j] != kNoMatch) {
        skip_right[j] = skip_right[match_[j] + 1];
        branch_end[j] = branch_end[match_[j] + 1];
      } else if (s == kSymPush) {
        skip_right[j] = static_cast<uint32_t>(j);
        branch_end[j] = kNoMatch;
      } else if (s == kSymPop) {
        skip_right[j] = static_cast<uint32_t>(j);
        branch_end[j] = static_cast<uint32_t>(j);
      } else {
        skip_right[j] = static_cast<uint32_t>(j);
        branch_end[j] = branch_end[after];
      }
    }
  }

  // Going left: the last module at or before j that is not ignored, not a '[' (climbed
  // out of) and not a completed branch; an unmatched ']' stops it; kNoMatch past the start.
  void compute_left_table(const Word& w, const std::vector<uint8_t>& ignored, ContextTables& t) {
    const size_t n = w.size();
    std::vector<uint32_t>& skip_left = t.skip_left;
    skip_left.assign(n, kNoMatch);
    for (size_t j = 0; j < n; ++j) {
      const SymbolId s = w.modules[j].symbol;
      if (s == kSymPush || ignored[s]) skip_left[j] = j ? skip_left[j - 1] : kNoMatch;
      else if (s == kSymPop && match_[j] != kNoMatch) skip_left[j] = match_[j] ? skip_left[match_[j] - 1] : kNoMatch;
      else skip_left[j] = static_cast<uint32_t>(j);
    }
  }

  bool ignored(SymbolId s) const { return g_.ignored[s] != 0; }

  // The new word a forward pass has written so far: its left-context table grows with it
  // (compute_left_table's rule, one module at a time).
  void extend_left_tables(const Word& w) {
    for (size_t j = new_skip_left_.size(); j < w.size(); ++j) {
      const SymbolId s = w.modules[j].symbol;
      const uint32_t before = j ? new_skip_left_[j - 1] : kNoMatch;
      if (s == kSymPush) {
        new_open_.push_back(static_cast<uint32_t>(j));
        new_skip_left_.push_back(before);
      } else if (ignored(s)) {
        new_skip_left_.push_back(before);
      } else if (s == kSymPop && !new_open_.empty()) {
        const uint32_t open = new_open_.back();
        new_open_.pop_back();
        new_skip_left_.push_back(open ? new_skip_left_[open - 1] : kNoMatch);
      } else {
        new_skip_left_.push_back(static_cast<uint32_t>(j));
      }
    }
  }

  // The new word a backward pass has written so far, stored last module first (storage
  // index r; the module to the right of r is r - 1): its right-context tables grow with it
  // (compute_right_tables' rule), in storage indices, kEnd for "past the word's end".
  static constexpr uint32_t kEnd = 0xFFFFFFFEu;
  void extend_right_tables(const Word& rev) {
    for (size_t r = new_match_.size(); r < rev.size(); ++r) {
      const SymbolId s = rev.modules[r].symbol;
      const uint32_t self = static_cast<uint32_t>(r);
      const uint32_t after = r ? self - 1 : kEnd;
      auto at = [](const std::vector<uint32_t>& t, uint32_t k) { return k == kEnd ? kEnd : t[k]; };
      new_match_.push_back(kNoMatch);
      if (s == kSymPop) {
        new_open_.push_back(self);  // a ']' waits for its '['
      } else if (s == kSymPush && !new_open_.empty()) {
        new_match_[r] = new_open_.back();
        new_match_[new_open_.back()] = self;
        new_open_.pop_back();
      }
      new_skip_ignored_.push_back(ignored(s) ? at(new_skip_ignored_, after) : self);
      uint32_t skip = self, end;
      if (ignored(s)) {
        skip = at(new_skip_right_, after);
        end = at(new_branch_end_, after);
      } else if (s == kSymPush && new_match_[r] != kNoMatch) {
        const uint32_t close = new_match_[r];
        const uint32_t past = close ? close - 1 : kEnd;
        skip = at(new_skip_right_, past);
        end = at(new_branch_end_, past);
      } else if (s == kSymPush) {
        end = kNoMatch;
      } else if (s == kSymPop) {
        end = self;
      } else {
        end = at(new_branch_end_, after);
      }
      new_skip_right_.push_back(skip);
      new_branch_end_.push_back(end);
    }
  }

  // A word as right context sees it, in reading order 0..n (n: past its end): the word
  // before the pass (its tables as compute_right_tables made them), or a backward pass's new
  // word (stored reversed, its tables in storage indices).
  struct RightView {
    const Word* w;
    const std::vector<uint32_t> *match, *skip_ignored, *skip_right, *branch_end;
    size_t n;
    bool reversed;
    bool ring;
    const Module& at(size_t j) const { return w->modules[reversed ? n - 1 - j : j]; }
    uint32_t get(const std::vector<uint32_t>& t, size_t j) const {
      if (!reversed) return t[j];
      if (j >= n) return static_cast<uint32_t>(n);
      const uint32_t v = t[n - 1 - j];
      return v == kNoMatch ? kNoMatch : v == kEnd ? static_cast<uint32_t>(n) : static_cast<uint32_t>(n - 1 - v);
    }
  };

  // ABOP 1.8: going left, skip completed branches ("[...]" before us) and climb out of
  // the branch we are in (its "["), so the context is the module below on the path.
  // `end` is the predecessor's place in `w` (the context ends just before it).
  bool match_left(const std::vector<PatternModule>& context, const Word& w, const std::vector<uint32_t>& skip_left,
                  size_t end, bool ring) {
    const size_t n = w.size();
    uint32_t j = end ? static_cast<uint32_t>(end - 1) : kNoMatch;
    for (size_t k = context.size(); k-- > 0;) {
      ++context_steps_;
      if (j != kNoMatch) j = skip_left[j];
      // A ring L-system (CPFG manual 3.1.1): before the first module comes the last.
      if (j == kNoMatch && ring && n > 0) j = skip_left[n - 1];
      if (j == kNoMatch) return false;
      const Module& m = w.modules[j];
      if (m.symbol == kSymPop) return false;  // an unmatched ']'
      const PatternModule& pm = context[k];
      if (m.symbol != pm.symbol || m.param_count != pm.arity) return false;
      bind(pm, w.params_of(m));
      j = j ? j - 1 : kNoMatch;
    }
    return true;
  }

  // ABOP 1.8: going right, skip whole branches the pattern does not enter; '[' in the
  // pattern enters a branch, ']' in the pattern skips the rest of the current branch;
  // the end of the current branch ends the context. `j` is the first module after the predecessor.
  bool match_right(const std::vector<PatternModule>& context, const RightView& v, size_t j) {
    const size_t n = v.n;
    const bool ring = v.ring;
    entered_.clear();
    for (size_t k = 0; k < context.size(); ++k) {
      ++context_steps_;
      const PatternModule& pm = context[k];
      // A ring L-system (CPFG manual 3.1.1): after the last module comes the first.
      if (j >= n && ring && n > 0 && entered_.empty()) j = 0;
      if (j >= n) return false;
      if (pm.symbol == kSymPush) {
        j = v.get(*v.skip_ignored, j);
        if (j >= n || v.at(j).symbol != kSymPush) return false;
        entered_.push_back(static_cast<uint32_t>(j));
        ++j;
        continue;
      }
      if (has_rest_of_branch_ && pm.symbol == rest_of_branch_ && pm.arity == 0) {
        // cpfg's `=` in a right context (generate.c: skipright): the rest of the branch the
        // pattern is in, whatever it holds, up to its `]`.
        const size_t close = !entered_.empty() ? v.get(*v.match, entered_.back()) : v.get(*v.branch_end, j);
        if (close >= n) return false;
        j = close;
        continue;
      }
      if (pm.symbol == kSymPop) {
        if (v.get(*v.skip_ignored, j) >= n) return false;
        size_t close;
        if (!entered_.empty()) {
          close = v.get(*v.match, entered_.back());
          entered_.pop_back();
        } else {
          close = v.get(*v.branch_end, j);
        }
        if (close >= n) return false;
        j = close + 1;
        continue;
      }
      j = v.get(*v.skip_right, j);
      if (j >= n && ring && n > 0 && entered_.empty()) j = v.get(*v.skip_right, 0);
      if (j >= n) return false;
      const Module& m = v.at(j);
      if (m.symbol == kSymPush || m.symbol == kSymPop) return false;  // an unclosed '[', the branch's end
      if (m.symbol != pm.symbol || m.param_count != pm.arity) return false;
      bind(pm, v.w->params_of(m));
      ++j;
    }
    return true;
  }

  // Binds the predecessor and contexts of `p` at module i; false if they do not match.
  // New context (p.new_left, p.new_right) reads the new word this pass has written: before
  // the predecessor's place in a forward pass, after it in a backward one; it never wraps.
  bool matches(const Production& p, size_t i, const Module& m) {
    bind(p.predecessor, in_->params_of(m));
    // A cpfg predecessor's further modules: the very next ones (tail_), same symbol and count.
    for (size_t k = 0; k < p.predecessor_tail.size(); ++k) {
      const PatternModule& pm = p.predecessor_tail[k];
      if (k >= tail_.count) return false;
      const size_t j = tail_.first + static_cast<size_t>(tail_.step * static_cast<ptrdiff_t>(k));
      if (tail_.active && !(*tail_.active)[j]) return false;
      if (tail_.depth && stack_depth_[j] != tail_.depth) return false;
      const Module& next = tail_.word->modules[j];
      if (next.symbol != pm.symbol || next.param_count != pm.arity) return false;
      bind(pm, tail_.word->params_of(next));
    }
    // The tables and ring of the L-system whose production this is (sub-L-systems).
    const ContextTables& t = tables_[per_lsystem_context_ ? lsystem_ : 0];
    const bool ring = per_lsystem_context_ ? g_.ring_in(lsystem_) : g_.ring;
    if (!p.left_context.empty()) {
      const bool ok = p.new_left ? match_left(p.left_context, *out_, new_skip_left_, out_->size(), false)
                                 : match_left(p.left_context, *in_, t.skip_left, i, ring);
      if (!ok) return false;
    }
    if (!p.right_context.empty()) {
      const bool ok =
          p.new_right
              ? match_right(p.right_context,
                            RightView{&reversed_, &new_match_, &new_skip_ignored_, &new_skip_right_, &new_branch_end_,
                                      reversed_.size(), true, false},
                            0)
              : match_right(p.right_context,
                            RightView{in_, &match_, &t.skip_ignored, &t.skip_right, &t.branch_end, in_->size(), false,
                                      ring},
                            i + 1 + p.predecessor_tail.size());
      if (!ok) return false;
    }
    return true;
  }

  const Production* choose(size_t i, const Module& m, Rng& rng) {
    current = i;
    const std::vector<uint32_t>& rules = by_symbol_[m.symbol];
    bool arity_seen = false;
    candidates_.clear();
    double total = 0;
    for (uint32_t r : rules) {
      const Production& p = productions_[r];
      if (p.lsystem != lsystem_) continue;  // another L-system's (sub-L-systems)
      if (p.predecessor.arity != m.param_count) continue;
      arity_seen = true;
      if (!matches(p, i, m)) continue;
      current_production = &p;
      // cpfg's statements before the condition run on every match (CPFG manual 3.2).
      if (p.before.kind != Expr::Kind::kNone) g_.program.eval(p.before, slots_.data(), &rng, context_);
      if (p.condition.kind != Expr::Kind::kNone && g_.program.eval(p.condition, slots_.data(), &rng, context_) == 0.0)
        continue;
      if (p.probability.kind == Expr::Kind::kNone) {
        if (candidates_.empty()) return &p;  // first candidate is deterministic: apply it
        continue;                            // deterministic ones after stochastic: ignored
      }
      double w = g_.program.eval(p.probability, slots_.data(), &rng, context_);
      if (w < 0) throw DeriveFailure{p.probability.loc, "a probability must not be negative (it is " + std::to_string(w) + ")"};
      // A candidate with statements keeps its slots (its locals): rebinding could not redo them.
      if (p.has_statements()) {
        if (candidate_slots_.size() <= candidates_.size()) candidate_slots_.resize(candidates_.size() + 1);
        candidate_slots_[candidates_.size()].assign(slots_.begin(), slots_.end());
      }
      candidates_.push_back({&p, w});
      total += w;
    }
    // A module no production of its symbol takes with its parameter count: an error in
    // sylva's format; in a cpfg file no match, as cpfg's PredDiff compares the counts.
    if (!arity_seen && !g_.cpfg && !sub_lsystems_) {
      const Production& p = productions_[rules[0]];
      current_production = &p;
      throw DeriveFailure{p.loc, "parameter count: module has " + std::to_string(m.param_count) +
                                     (m.param_count == 1 ? " parameter" : " parameters") +
                                     " but the production expects " + std::to_string(p.predecessor.arity)};
    }
    if (candidates_.empty()) return nullptr;
    if (total <= 0) {
      // Normalising weights that sum to 0 is a division by zero: every matching
      // production was switched off at once, which is almost surely a mistake.
      const Production& first = *candidates_.front().first;
      current_production = &first;
      throw DeriveFailure{first.probability.loc,
                          "the probabilities of the matching productions sum to 0 (nothing to choose from)"};
    }
    if (!std::isfinite(total)) {
      // Finite weights whose sum overflows (1e308 + 1e308): the same choice, in proportion,
      // from the weights divided by the largest; otherwise every seed would pick the last.
      double largest = 0;
      for (const auto& c : candidates_) largest = std::max(largest, c.second);
      total = 0;
      for (auto& c : candidates_) total += c.second /= largest;
    }
    double u = rng.next_double() * total;
    size_t picked = candidates_.size() - 1;
    for (size_t k = 0; k < candidates_.size(); ++k) {
      if (u < candidates_[k].second) {
        picked = k;
        break;
      }
      u -= candidates_[k].second;
    }
    const Production* pick = candidates_[picked].first;
    // Rebind the chosen production's parameters (later candidates overwrote the slots).
    if (pick->has_statements()) slots_ = candidate_slots_[picked];
    else matches(*pick, i, m);
    return pick;
  }

  void apply(const Production& p, size_t i, Rng& rng, bool keyed) {
    Word& out = *out_;
    const Successor& s = p.successor;
    if (out.modules.size() + out.params.size() + s.modules.size() + s.args.size() > max_modules_) too_many();
    if ((work_ += s.modules.size()) > work_budget_) over_budget();
    if (out.params.size() > kMaxParams) too_many_params();
    const size_t first_new = out.modules.size();
    if (p.after.kind != Expr::Kind::kNone) {  // cpfg's statements after the condition
      current = i;
      current_production = &p;
      g_.program.eval(p.after, slots_.data(), &rng, context_);
    }
    if (s.all_constant) {
      const uint32_t base = static_cast<uint32_t>(out.params.size());
      for (const Module& pm : s.prebuilt.modules)
        out.modules.push_back(Module{pm.symbol, pm.param_count, pm.param_begin + base});
      out.params.insert(out.params.end(), s.prebuilt.params.begin(), s.prebuilt.params.end());
    } else {
      // Slots were bound by choose() (the direct path only takes constant successors).
      current = i;
      current_production = &p;
      for (const SuccessorModule& sm : s.modules) {
        out.modules.push_back(Module{sm.symbol, sm.arg_count, static_cast<uint32_t>(out.params.size())});
        for (uint16_t k = 0; k < sm.arg_count; ++k)
          out.params.push_back(g_.program.eval(s.args[sm.first_arg + k], slots_.data(), &rng, context_));
      }
    }
    if (keyed) {
      const uint64_t key = in_->lineage[i];
      for (size_t j = first_new; j < out.modules.size(); ++j)
        out.lineage.push_back(mix_pair(key, j - first_new + 1));
    }
  }

  const Grammar& g_;
  const std::vector<Production>& productions_;
  const std::vector<std::vector<uint32_t>>& by_symbol_;
  uint64_t seed_;
  uint64_t max_modules_;
  EvalContext* context_;  // the L-system's global variables (cpfg); null-free: never null
  SymbolId rest_of_branch_ = 0;  // a cpfg file's `=` (match_right), when has_rest_of_branch_
  bool has_rest_of_branch_ = false;
  bool uses_context_ = false;
  const Word* in_ = nullptr;
  Word* out_ = nullptr;
  std::vector<double> slots_;
  std::vector<const Production*> direct_;
  std::vector<uint32_t> match_;
  std::vector<uint32_t> open_;
  std::vector<uint32_t> entered_;
  // Where matches() looks for a cpfg predecessor's further modules: the k-th (k < count) is
  // word->modules[first + step * k]; with `active`, only a module flagged there; with
  // `depth` (expand()'s stack), only one of that depth, of the same successor.
  struct TailView {
    const Word* word = nullptr;
    size_t first = 0;
    ptrdiff_t step = 1;
    size_t count = 0;
    const std::vector<uint8_t>* active = nullptr;
    int depth = 0;
  };
  TailView tail_;
  bool uses_tails_ = false;  // some production has a predecessor of several modules (else tail_ is never read)
  // Sub-L-systems (CPFG manual 7.2; cpfg's CheckPred): the L-system whose productions apply
  // now (its index in Grammar::lsystem_labels), and the ones a $ returns to.
  bool sub_lsystems_ = false;
  SymbolId sub_call_ = 0;  // `?`, as in ?(label, s)
  uint32_t lsystem_ = 0;
  std::vector<uint32_t> lsystem_stack_;
  std::vector<int> depth_limits_;  // set_depth_limits
  int pass_depth_ = 0;

  // A word is read from its start in the main L-system.
  void enter_word() {
    lsystem_ = 0;
    lsystem_stack_.clear();
  }

  // After module i of `w` is read: ?(label, s) makes L-system `label` current; $ returns to
  // the one before (at the top level it stays the main one, as cpfg warns and goes on).
  void track_lsystem(const Word& w, size_t i) {
    const Module& m = w.modules[i];
    if (m.symbol == sub_call_ && m.param_count >= 1) {
      const double label = w.params_of(m)[0];
      const auto& labels = g_.lsystem_labels;
      size_t k = 0;
      while (k < labels.size() && static_cast<double>(labels[k]) != label) ++k;
      if (k == labels.size()) {
        current = i;
        in_ = &w;  // the message names the module in this word
        current_production = nullptr;
        throw DeriveFailure{{}, "?(" + module_number(label) + ", ...) calls an L-system the file does not define "
                                "(its labels: " + label_list() + ")"};
      }
      lsystem_stack_.push_back(lsystem_);
      lsystem_ = static_cast<uint32_t>(k);
    } else if (m.symbol == kSymLevel) {
      if (!lsystem_stack_.empty()) {
        lsystem_ = lsystem_stack_.back();
        lsystem_stack_.pop_back();
      } else {
        lsystem_ = 0;
      }
    }
  }
  std::string label_list() const {
    std::string out;
    for (int64_t l : g_.lsystem_labels)
      if (l >= 0) out += (out.empty() ? "" : ", ") + std::to_string(l);
    return out;
  }
  static std::string module_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }
  std::vector<ContextTables> tables_;  // one set, or one per L-system when per_lsystem_context_
  bool per_lsystem_context_ = false;
  bool uses_left_context_ = false, uses_right_context_ = false;  // old context (the word before the pass)
  bool uses_new_left_ = false, uses_new_right_ = false;          // new context (grammar.h)
  // The new word's context tables (extend_left_tables, extend_right_tables) and a backward
  // pass's new word, stored reversed.
  std::vector<uint32_t> new_skip_left_, new_open_, new_match_, new_skip_ignored_, new_skip_right_, new_branch_end_;
  Word reversed_;
  uint64_t context_steps_ = 0;
  uint64_t work_ = 0, work_budget_ = UINT64_MAX;
  const char* budget_what_ = "the interpretation";
  Word stack_, successor_;
  std::vector<int> stack_depth_;
  std::vector<std::pair<const Production*, double>> candidates_;
  std::vector<std::vector<double>> candidate_slots_;  // by candidate, for those with statements
};

// Removes, for each %, the rest of its branch up to (not including) the closing ']' — or,
// in a cpfg file with sub-L-systems, the $ that ends the sub-L-system it is in (cpfg's
// SkipCutPart).
void apply_cut(Word& w, const Grammar& g) {
  const size_t n = w.size();
  const bool keyed = !w.lineage.empty();
  SymbolId call = 0;
  const bool subs = g.has_sub_lsystems() && g.symbols.find("?", &call);
  size_t out = 0, out_param = 0;
  for (size_t i = 0; i < n;) {
    if (w.modules[i].symbol == kSymCut) {
      int depth = 0, sub = 0;
      size_t j = i + 1;
      for (; j < n; ++j) {
        const Module& m = w.modules[j];
        const SymbolId s = m.symbol;
        if (s == kSymPush) ++depth;
        else if (s == kSymPop && depth-- == 0) break;
        else if (subs && s == call && m.param_count > 0) ++sub;
        else if (subs && s == kSymLevel && sub-- == 0) break;
      }
      i = j;
      continue;
    }
    Module m = w.modules[i];
    for (uint16_t k = 0; k < m.param_count; ++k) w.params[out_param + k] = w.params[m.param_begin + k];
    m.param_begin = static_cast<uint32_t>(out_param);
    out_param += m.param_count;
    w.modules[out] = m;
    if (keyed) w.lineage[out] = w.lineage[i];
    ++out;
    ++i;
  }
  w.modules.resize(out);
  w.params.resize(out_param);
  if (keyed) w.lineage.resize(out);
}

Diagnostic failure_diagnostic(const Grammar& g, const Rewriter& r, const std::string& message, SourceLoc loc,
                              const char* what, int64_t step) {
  std::string text = message;
  const Word* in = r.current_word();
  if (r.current_production) {
    const Production& p = *r.current_production;
    text += ", in production '" + p.text + "' at " + std::to_string(p.loc.line) + ":" +
            std::to_string(p.loc.column);
    if (in && r.current < in->size()) text += " rewriting module " + module_text(*in, r.current, g.symbols);
    if (loc.line == 0) loc = p.loc;
  }
  text += std::string(" at ") + what + " " + std::to_string(step);
  return g.error_at(loc, text);
}

void reserve_for_growth(Word& out, size_t in_size, double growth, uint64_t max_modules) {
  double want = static_cast<double>(in_size) * growth * 1.05 + 16;
  size_t cap = static_cast<size_t>(std::min<double>(want, static_cast<double>(max_modules) + 1));
  if (out.modules.capacity() < cap) out.modules.reserve(cap);
}

// The blocks of a cpfg file (CPFG manual 4.1), in the order derive() runs them.
enum class Block : uint64_t { kStart, kStartEach, kEndEach, kEnd };

// Runs one block over the globals, its random stream keyed by (seed, block, step); a
// srand() in it sets the derivation's seed from then on (*seed).
void run_block(const Grammar& g, Block block, int64_t step, uint64_t* seed, EvalContext& context) {
  const Expr* const exprs[] = {&g.start_block, &g.start_each_block, &g.end_each_block, &g.end_block};
  const Expr& e = *exprs[static_cast<size_t>(block)];
  const std::vector<Expr>& subs = g.sub_blocks[static_cast<size_t>(block)];
  if (e.kind == Expr::Kind::kNone && subs.empty()) return;
  Rng rng(mix_pair(*seed, kBlockStreamBase + 4 * static_cast<uint64_t>(step) + static_cast<uint64_t>(block)));
  context.reseeded = false;
  // The main L-system's block, then its sub-L-systems' (cpfg's Evaluate*Statements, in order).
  if (e.kind != Expr::Kind::kNone) g.program.eval(e, nullptr, &rng, &context);
  for (const Expr& sub : subs) g.program.eval(sub, nullptr, &rng, &context);
  if (context.reseeded) *seed = context.reseed;
}

}  // namespace

namespace {

// Applies `productions` (those `rewriter` was made with) to `cur` recursively, up to
// `max_depth` passes, leaving the result in `cur` (`next` is scratch): homomorphism and
// decomposition alike (CPFG manual 4.3, 4.4). Without context, depth first (pass d
// rewrites what pass d - 1 produced, with stream `stream_base + d`); with context, pass by
// pass over the whole word, each with its context in the word of the pass before. Returns
// the passes performed; with `count_left`, `*left` counts the modules left unexpanded at
// the depth limit that a production could still rewrite. Throws as the rewriter does
// (DeriveCancelled when `progress` is cancelled between passes).
int apply_recursively(Rewriter& rewriter, const std::vector<Production>& productions,
                      const std::vector<std::vector<uint32_t>>& by_symbol, Word& cur, Word& next, uint64_t stream_base,
                      int max_depth, uint64_t budget, const Progress& progress, bool count_left, uint64_t* left) {
  *left = 0;
  max_depth = rewriter.deepest_limit(max_depth);  // sub-L-systems' own depths: the deepest bounds the passes
  const bool context =
      std::any_of(productions.begin(), productions.end(), [](const Production& p) { return p.has_context(); });
  if (!context) {
    // Without context, pass d reads nothing but the modules pass d - 1 produced: expand
    // each module depth first, so unexpandable modules are not copied once per pass.
    int deepest = 0;
    next.clear();
    rewriter.expand(cur, next, stream_base, max_depth, budget, progress, &deepest, left);
    if (!count_left) *left = 0;
    std::swap(cur, next);
    return std::min(deepest + 1, max_depth);
  }
  // Context reads the whole word of the pass before: pass by pass, each over the word.
  std::vector<uint8_t> active(cur.size(), 1), next_active;
  int depth = 1;
  for (; depth <= max_depth; ++depth) {
    if (progress.cancelled()) throw DeriveCancelled{};
    next.clear();
    next_active.clear();
    rewriter.current_production = nullptr;
    rewriter.current_depth = depth;
    rewriter.set_pass_depth(depth);
    // Passes until nothing expands: each reports within the pass only (how many passes
    // there will be is not known), monotone across passes by the share scheme 1 - 2^-depth.
    const double first = 1 - std::ldexp(1.0, -(depth - 1)), last = 1 - std::ldexp(1.0, -depth);
    rewriter.rewrite(cur, next, stream_base + static_cast<uint64_t>(depth), &active, &next_active,
                     progress.part(first, last), "interpret");
    const bool changed = std::find(next_active.begin(), next_active.end(), 1) != next_active.end();
    std::swap(cur, next);
    std::swap(active, next_active);
    if (!changed) break;
  }
  // Modules produced by the last pass that still have a production: left unexpanded.
  if (depth > max_depth && count_left)
    for (size_t i = 0; i < cur.size(); ++i)
      if (active[i] && !by_symbol[cur.modules[i].symbol].empty()) ++*left;
  return std::min(depth, max_depth);
}

// What a homomorphism or decomposition may write in one application: 16 × --max-modules
// (docs/limits.md "Work"), saturating.
uint64_t recursion_budget(uint64_t max_modules) {
  return max_modules > UINT64_MAX / kInterpretBudgetFactor ? UINT64_MAX : max_modules * kInterpretBudgetFactor;
}

// A maximum depth by L-system: the main one's `main`, each sub-L-system's its own `field`.
std::vector<int> depths_by_lsystem(const Grammar& g, int Grammar::SubLsystem::*field, int main) {
  std::vector<int> depths{main};
  for (const Grammar::SubLsystem& s : g.sub_lsystems) depths.push_back(s.*field);
  return depths;
}

// The globals before the Start block: the arrays' initialisers, every other one 0.
std::vector<double> initial_globals(const Grammar& g) {
  std::vector<double> v = g.global_initial;
  v.resize(g.global_names.size(), 0.0);
  return v;
}

}  // namespace

struct Derivation::Impl {
  Impl(const Grammar& grammar, const DeriveOptions& o)
      : g(grammar),
        options(o),
        steps(o.steps.value_or(grammar.steps)),
        seed(o.seed.value_or(grammar.seed)),
        globals(initial_globals(grammar)),
        context{globals.data()} {
    if (grammar.uses_files) {
      // fopen writes and reads beside the model (docs/cpfg.md "Files"); a model of no file
      // ("<string>") has no folder.
      if (!grammar.file.empty() && grammar.file.front() != '<') {
        const std::filesystem::path folder = std::filesystem::path(grammar.file).parent_path();
        files.folder = folder.empty() ? "." : folder.string();
      }
      context.files = &files;
    }
    passes.reserve(grammar.passes.size());
    for (const Grammar::Pass& pass : grammar.passes)
      passes.emplace_back(grammar, grammar.productions, pass.by_symbol, seed, o.max_modules, &context);
    active = &passes[0];
    if (!grammar.decomposition.empty())
      decomposer.emplace(grammar, grammar.decomposition, grammar.decomposition_by_symbol, seed, o.max_modules,
                         &context);
    if (decomposer && grammar.has_sub_lsystems())
      decomposer->set_depth_limits(depths_by_lsystem(grammar, &Grammar::SubLsystem::decomposition_depth,
                                                     grammar.decomposition_depth));
  }

  // The decomposition productions applied to `cur` (CPFG manual 4.4), each step's from
  // its own streams; the rewriter that failed, if one throws, is `active`.
  void decompose(int64_t at) {
    if (!decomposer) return;
    active = &*decomposer;
    decomposer->set_seed(seed);
    decomposer->current_production = nullptr;
    // Each step's decomposition has the budget of one interpretation (the rewriter holds
    // every word it writes to --max-modules).
    const uint64_t budget = recursion_budget(options.max_modules);
    decomposer->set_work_budget(budget, "the decomposition");
    uint64_t left = 0;
    apply_recursively(*decomposer, g.decomposition, g.decomposition_by_symbol, cur, next,
                      kDecompositionStreamBase + static_cast<uint64_t>(at) * (kMaxDecompositionDepth + 2),
                      g.decomposition_depth, budget, options.progress, false, &left);
    active = &passes[0];
  }

  // Every rewriter's production cleared (an error after this names none) and seed set.
  void reset_rewriters() {
    for (Rewriter& r : passes) {
      r.current_production = nullptr;
      r.set_seed(seed);
    }
  }

  // on_step's "no" is a cancellation too: its Diagnostic has `cancelled` set.
  Diagnostic stopped_at(int64_t at) const {
    Diagnostic d = g.error_at({}, "cancelled at step " + std::to_string(at));
    d.cancelled = true;
    return d;
  }

  const Grammar& g;
  const DeriveOptions& options;
  int64_t steps;  // the derivation length; a stop() (CPFG manual 5.6) shortens it
  uint64_t seed;
  // A cpfg file's global variables, 0 until a block or a production assigns them.
  std::vector<double> globals;
  EvalContext context;
  ModelFiles files;                    // what fopen opened (context.files points here)
  std::vector<Rewriter> passes;        // one per pass of a step (Grammar::passes)
  std::optional<Rewriter> decomposer;  // with decomposition productions only
  Rewriter* active = nullptr;          // the one whose production an error names
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  Word cur, next;
  uint64_t peak = 0;
  double growth = 2.0;
  int64_t step = 0;
  bool started = false, failed = false;
};

Derivation::Derivation(const Grammar& grammar, const DeriveOptions& options)
    : impl_(std::make_unique<Impl>(grammar, options)) {}
Derivation::~Derivation() = default;

int64_t Derivation::step() const { return impl_->step; }
int64_t Derivation::steps() const { return impl_->steps; }
Word& Derivation::word() { return impl_->cur; }

Status Derivation::start() {
  Impl& m = *impl_;
  const Grammar& g = m.g;
  assert(!m.started);
  m.started = true;
  m.failed = true;  // until it succeeds
  if (g.axiom.size() + g.axiom.params.size() > m.options.max_modules)
    return g.error_at(g.axiom_loc, "the axiom exceeds --max-modules (" + std::to_string(m.options.max_modules) +
                                       " modules), each parameter counting as a module");
  try {
    run_block(g, Block::kStart, 0, &m.seed, m.context);
  } catch (const EvalError& e) {
    return g.error_at(e.loc, e.message + " (in the Start block)");
  }
  m.cur = g.axiom;
  if (g.axiom_successor) {
    // The axiom draws random numbers: evaluate its arguments from this seed's stream.
    Rng rng = axiom_rng(m.seed);
    size_t k = 0;
    try {
      for (const SuccessorModule& sm : g.axiom_successor->modules)
        for (uint16_t a = 0; a < sm.arg_count; ++a)
          m.cur.params[k++] = g.program.eval(g.axiom_successor->args[sm.first_arg + a], nullptr, &rng, &m.context);
    } catch (const EvalError& e) {
      return g.error_at(e.loc, e.message + " (in the axiom)");
    }
  }
  if (g.uses_random) {
    m.cur.lineage.resize(m.cur.size());
    for (size_t i = 0; i < m.cur.size(); ++i) m.cur.lineage[i] = mix_pair(kAxiomKeyBase, i);
  }
  const bool cut_now = g.uses_cut && !g.cpfg;  // a cpfg file's % cuts when the next step reads it
  if (cut_now) apply_cut(m.cur, g);
  m.reset_rewriters();
  if (m.decomposer) {
    try {
      m.decompose(0);
      if (cut_now) apply_cut(m.cur, g);
    } catch (const DeriveCancelled&) {
      return cancelled_diagnostic();
    } catch (const DeriveFailure& f) {
      return failure_diagnostic(g, *m.active, f.message, f.loc, "step", 0);
    } catch (const EvalError& e) {
      return failure_diagnostic(g, *m.active, e.message, e.loc, "step", 0);
    }
  }
  m.peak = m.cur.capacity_bytes();
  if (m.context.stop) m.steps = 0;  // stop() in the Start block or the axiom's decomposition
  if (m.options.on_step && !m.options.on_step(0, m.cur)) return m.stopped_at(0);
  m.failed = false;
  return {};
}

Status Derivation::advance() {
  Impl& m = *impl_;
  const Grammar& g = m.g;
  assert(m.started && !m.failed && m.step < m.steps);
  m.failed = true;  // until it succeeds
  const int64_t step = ++m.step;
  try {
    if (m.options.progress.cancelled()) return cancelled_diagnostic();
    m.reset_rewriters();
    run_block(g, Block::kStartEach, step, &m.seed, m.context);
    m.reset_rewriters();
    // Step k is the k-th equal share of the whole (the last steps are the longest, so
    // the bar slows down; it never goes back); its passes share it equally.
    const size_t pass_count = m.passes.size();
    const double share = 1.0 / static_cast<double>(m.steps) / static_cast<double>(pass_count);
    for (size_t k = 0; k < pass_count; ++k) {
      m.active = &m.passes[k];
      // cpfg (generate.c's ApplyProd): a % of the word before the step, which no production
      // rewrites, drops itself and the rest of its branch as the step reads it.
      if (g.uses_cut && g.cpfg) apply_cut(m.cur, g);
      const uint64_t before = m.cur.size();
      m.next.clear();
      reserve_for_growth(m.next, m.cur.size(), m.growth, m.options.max_modules);
      if (g.uses_random) m.next.lineage.reserve(m.next.modules.capacity());
      const double begin = static_cast<double>(step - 1) / static_cast<double>(m.steps) + share * static_cast<double>(k);
      const Progress pass_progress = m.options.progress.part(begin, begin + share);
      // Pass 0 keeps the streams a one-pass grammar always had: the step's number.
      const uint64_t stream = static_cast<uint64_t>(step) | (static_cast<uint64_t>(k) << 56);
      m.passes[k].rewrite(m.cur, m.next, stream, nullptr, nullptr, pass_progress, "derive", g.passes[k].backward);
      if (g.uses_cut && !g.cpfg) apply_cut(m.next, g);
      if (step < m.steps || k + 1 < pass_count) pass_progress.report(1, "derive");  // the last 1 is the whole's
      m.peak = std::max<uint64_t>(m.peak, m.cur.capacity_bytes() + m.next.capacity_bytes());
      m.growth = before ? std::max(1.0, static_cast<double>(m.next.size()) / static_cast<double>(before)) : 2.0;
      std::swap(m.cur, m.next);
    }
    m.active = &m.passes[0];
    if (m.decomposer) {
      m.decompose(step);
      if (g.uses_cut && !g.cpfg) apply_cut(m.cur, g);
    }
    m.reset_rewriters();
    run_block(g, Block::kEndEach, step, &m.seed, m.context);
    if (m.context.stop) m.steps = step;  // stop() (CPFG manual 5.6): this step is the last
    if (m.options.on_step && !m.options.on_step(step, m.cur)) return m.stopped_at(step);
  } catch (const DeriveCancelled&) {
    return cancelled_diagnostic();
  } catch (const DeriveFailure& f) {
    return failure_diagnostic(g, *m.active, f.message, f.loc, "step", step);
  } catch (const EvalError& e) {
    return failure_diagnostic(g, *m.active, e.message, e.loc, "step", step);
  } catch (const std::bad_alloc&) {
    return g.error_at({}, "out of memory at step " + std::to_string(step) +
                              "; lower --max-modules or the derivation length");
  }
  m.failed = false;
  return {};
}

Expected<Word> Derivation::finish(DeriveStats* stats) {
  Impl& m = *impl_;
  const Grammar& g = m.g;
  assert(m.started && !m.failed);
  try {
    m.reset_rewriters();
    run_block(g, Block::kEnd, m.steps, &m.seed, m.context);
    // The files a model left open are written now (cpfg's exit closes them).
    if (const std::string error = m.files.close_all(); !error.empty())
      return g.error_at({}, "a file the model wrote with fopen: " + error);
  } catch (const DeriveFailure& f) {
    return failure_diagnostic(g, m.passes[0], f.message, f.loc, "step", m.steps + 1);
  } catch (const EvalError& e) {
    return failure_diagnostic(g, m.passes[0], e.message, e.loc, "step", m.steps + 1);
  }
  if (stats) {
    stats->steps = m.step;
    stats->modules = m.cur.size();
    stats->peak_bytes = m.peak;
    stats->context_steps = 0;
    for (const Rewriter& r : m.passes) stats->context_steps += r.context_steps();
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - m.t0).count();
  }
  m.options.progress.report(1, "derive");
  m.cur.globals = m.globals;
  return std::move(m.cur);
}

Expected<Word> derive(const Grammar& g, const DeriveOptions& options, DeriveStats* stats) {
  Derivation d(g, options);
  if (Status s = d.start(); !s) return s.error();
  while (!d.done())
    if (Status s = d.advance(); !s) return s.error();
  return d.finish(stats);
}

Expected<Word> interpret(const Grammar& g, const Word& word, const DeriveOptions& options, InterpretStats* stats) {
  Word cur = word;
  if (g.homomorphism.empty()) return cur;
  const uint64_t seed = options.seed.value_or(g.seed);
  if (g.uses_random && cur.lineage.size() != cur.size()) {
    cur.lineage.resize(cur.size());
    for (size_t i = 0; i < cur.size(); ++i) cur.lineage[i] = mix_pair(kAxiomKeyBase, i);
  }
  Word next;
  // The globals as the derivation left them (a word from elsewhere: all 0).
  std::vector<double> globals = word.globals.size() == g.global_names.size() ? word.globals : initial_globals(g);
  EvalContext eval_context{globals.data()};
  Rewriter rewriter(g, g.homomorphism, g.homomorphism_by_symbol, seed, options.max_modules, &eval_context);
  if (g.has_sub_lsystems()) rewriter.set_depth_limits(depths_by_lsystem(g, &Grammar::SubLsystem::max_depth, g.max_depth));
  const uint64_t budget = recursion_budget(options.max_modules);
  rewriter.set_work_budget(budget);
  int depth = 0;  // passes performed, as stats report them
  uint64_t left = 0;
  try {
    depth = apply_recursively(rewriter, g.homomorphism, g.homomorphism_by_symbol, cur, next, kHomomorphismStreamBase,
                              g.max_depth, budget, options.progress, g.depth_warnings, &left);
  } catch (const DeriveCancelled&) {
    return cancelled_diagnostic();
  } catch (const DeriveFailure& f) {
    return failure_diagnostic(g, rewriter, f.message, f.loc, "interpretation depth", rewriter.current_depth);
  } catch (const EvalError& e) {
    return failure_diagnostic(g, rewriter, e.message, e.loc, "interpretation depth", rewriter.current_depth);
  }
  if (stats) {
    stats->depth = depth;
    stats->still_expandable = left;
    stats->work = rewriter.work();
  }
  cur.lineage.clear();
  cur.lineage.shrink_to_fit();
  options.progress.report(1, "interpret");
  return cur;
}

}  // namespace sylva::lsys
