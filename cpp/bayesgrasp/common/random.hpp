// Seeded randomness: every random number comes from an explicit std::mt19937_64 passed in.
#pragma once

#include <cstdint>
#include <random>

namespace bayesgrasp {

using Rng = std::mt19937_64;

/// Uniform in [0, 1) from the top 53 bits (the same stream on every platform with this engine).
inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// SplitMix64 finaliser: decorrelates nearby seeds (seed, seed + 1, ...) before seeding an engine.
inline std::uint64_t mix_seed(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace bayesgrasp
