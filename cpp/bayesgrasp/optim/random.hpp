// Small helpers on a seeded std::mt19937_64 (the optimisers' only source of randomness).
#pragma once

#include <cstdint>
#include <random>

namespace bayesgrasp::optim {

using Rng = std::mt19937_64;

/// Uniform in [0, 1) from the top 53 bits (same stream on every platform with this engine).
inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace bayesgrasp::optim
