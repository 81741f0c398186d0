#include "bayesgrasp/task/pose_density.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::task {

namespace {
void positive(double v, const char* name) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + ": must be positive and finite, got " + std::to_string(v));
}
}  // namespace

void PoseDensity::validate() const {
  positive(translation_scale, "translation_scale");
  positive(rotation_scale, "rotation_scale");
  if (!(wide_weight >= 0.0 && wide_weight <= 1.0))
    throw std::invalid_argument("wide_weight: must lie in [0, 1], got " + std::to_string(wide_weight));
  if (!(wide_factor >= 1.0) || !std::isfinite(wide_factor))
    throw std::invalid_argument("wide_factor: must be >= 1 and finite, got " + std::to_string(wide_factor));
}

double PoseDensity::operator()(double dt, double dr) const {
  const double a = dt / translation_scale, b = dr / rotation_scale;
  switch (kind) {
    case DensityKind::Laplace:
      return std::exp(-(a + b));
    case DensityKind::Gaussian:
      return std::exp(-0.5 * (a * a + b * b));
    case DensityKind::RegularisedGaussian: {
      const double k2 = wide_factor * wide_factor;
      return (1.0 - wide_weight) * std::exp(-0.5 * (a * a + b * b)) + wide_weight * std::exp(-0.5 * (a * a + b * b) / k2);
    }
  }
  return 0.0;
}

}  // namespace bayesgrasp::task
