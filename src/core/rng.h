// Deterministic random numbers. Every consumer derives its own stream from a seed and an
// index (pixel, light, path), so results never depend on thread scheduling.
#pragma once

#include <cstdint>

namespace lc {

// SplitMix64: turns (seed, index) into well-mixed stream seeds.
inline uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// PCG32 (O'Neill 2014), XSH-RR variant.
class Rng {
 public:
  Rng() : Rng(0, 0) {}
  Rng(uint64_t seed, uint64_t stream) { seedWith(seed, stream); }

  void seedWith(uint64_t seed, uint64_t stream) {
    state_ = 0;
    inc_ = (splitmix64(stream) << 1u) | 1u;
    next();
    state_ += splitmix64(seed);
    next();
  }
  uint32_t next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }
  // Uniform in [0, 1).
  float uniform() { return float(next() >> 8) * 0x1p-24f; }
  double uniformDouble() { return double((uint64_t(next()) << 21) ^ next()) * 0x1p-53; }
  // Uniform integer in [0, n).
  uint32_t below(uint32_t n) { return n == 0 ? 0 : uint32_t((uint64_t(next()) * n) >> 32); }

 private:
  uint64_t state_ = 0, inc_ = 1;
};

// Radical inverse in base 2 (van der Corput), for low-discrepancy point sets.
inline float radicalInverse2(uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
  return float(i) * 0x1p-32f;
}

inline float radicalInverse(uint32_t base, uint32_t i) {
  double inv = 1.0 / base, f = inv, r = 0;
  while (i > 0) {
    r += f * (i % base);
    i /= base;
    f *= inv;
  }
  return float(r);
}

}  // namespace lc
