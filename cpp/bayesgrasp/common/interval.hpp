// Scalar helpers on intervals.
#pragma once

#include <cmath>

namespace bayesgrasp {

/// x reflected into [lo, hi] (repeatedly, for excursions of several widths); lo if hi <= lo.
inline double reflect_into(double x, double lo, double hi) {
  const double w = hi - lo;
  if (w <= 0.0) return lo;
  double y = std::fmod(x - lo, 2.0 * w);
  if (y < 0.0) y += 2.0 * w;
  return lo + (y <= w ? y : 2.0 * w - y);
}

}  // namespace bayesgrasp
