// random.h — sylva's one random generator, SplitMix64 (Steele, Lea, Flood 2014): tiny
// state, fast to seed, identical on every machine. Every stream draws from it: a
// derivation's stable streams, the renderers' pixel and photon samples, a scatter's darts,
// the sway's phases.
//
// Stable streams (lsystem/): a module's draws come from a stream keyed by (seed, the module's
// lineage key, the derivation step), so editing one part of a grammar leaves the random
// numbers of every other part bit-identical. The generator is SplitMix64 (Steele, Lea,
// Flood 2014).
#pragma once

#include <cmath>
#include <cstdint>

namespace sylva {

// A 64-bit finaliser (SplitMix64/Murmur3 style): a good hash of one word.
constexpr uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Hash of an ordered pair, for deriving keys.
constexpr uint64_t mix_pair(uint64_t a, uint64_t b) {
  return mix64(a ^ mix64(b + 0x9e3779b97f4a7c15ULL));
}

// R2 (Roberts 2018): x_i = frac(offset + i·(1/g, 1/g²)), g the plastic number, in 64-bit
// fixed point so that point 10⁹ is as exact as point 1; unit_from_fixed maps a coordinate
// to [0, 1) with 53 bits.
constexpr uint64_t kR2Step0 = 0xC13FA9A902A6328FULL;  // 2^64 / g
constexpr uint64_t kR2Step1 = 0x91E10DA5C79E7B1CULL;  // 2^64 / g²
constexpr double unit_from_fixed(uint64_t x) { return static_cast<double>(x >> 11) * 0x1.0p-53; }

class Rng {
 public:
  explicit Rng(uint64_t state = 0) : state_(state) {}
  uint64_t next_u64() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  // Uniform in [0, 1) with 53 random bits.
  double next_double() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  // Uniform in [0, n) for n >= 1 (Lemire's multiply-shift; the bias is below 2^-64·n).
  uint64_t below(uint64_t n) {
    __extension__ using Uint128 = unsigned __int128;  // GCC and Clang
    return static_cast<uint64_t>((static_cast<Uint128>(next_u64()) * n) >> 64);
  }
  // Standard normal by Box–Muller (deterministic: one pair of uniform draws per call).
  // The counter: Rng(r.state()) continues r's stream.
  uint64_t state() const { return state_; }
  double next_gauss() {
    double u1 = 1.0 - next_double();  // (0, 1]: log never sees 0
    double u2 = next_double();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace sylva
