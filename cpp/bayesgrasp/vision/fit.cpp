#include "bayesgrasp/vision/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bayesgrasp::vision {

namespace {
// |q - s| evaluated as sqrt((dx^2 + dy^2) + dz^2) with the last step fused, a fixed rounding
// whatever the compiler vectorises.
double distance_to(const Vec3& q, const Eigen::Vector3f& s) {
  const Eigen::Vector2d dxy = q.head<2>() - s.head<2>().cast<double>();
  const double dz = q.z() - static_cast<double>(s.z());
  return std::sqrt(std::fma(dz, dz, dxy.squaredNorm()));
}
}  // namespace

void nearest_samples(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, const Iso3& T,
                     std::vector<double>& distance, std::vector<int>& index) {
  distance.resize(scene.size());
  index.resize(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const Vec3 q = T * scene[i];
    const int k = model.grid.nearest(q);
    index[i] = k;
    distance[i] = k >= 0 ? distance_to(q, model.samples.points[k]) : std::numeric_limits<double>::infinity();
  }
}

Fit measure_fit(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, const Iso3& T, double tau) {
  std::vector<double> d;
  std::vector<int> idx;
  nearest_samples(model, scene, T, d, idx);
  Fit f;
  int n_in = 0;
  double s_in = 0, s_all = 0;
  for (double di : d) {
    if (di < tau) {
      ++n_in;
      s_in += di * di;
    }
    const double c = std::min(di, tau);
    s_all += c * c;
  }
  f.fitness = scene.empty() ? 0.0 : static_cast<double>(n_in) / scene.size();
  f.rmse = n_in ? std::sqrt(s_in / n_in) : 0.0;
  f.delta = scene.empty() ? tau : std::sqrt(s_all / scene.size());
  return f;
}

double phi(double delta, double sigma) { return std::exp(-delta * delta / (2 * sigma * sigma)); }

double up_cosine(const Iso3& T, const Eigen::Vector3d& up) {
  return T.linear().row(2).dot(up);  // the model's +z in the scene frame is R^T e_z
}

double selection_cost(const Fit& fit, const Iso3& T, double tau, const Eigen::Vector3d& up, const UpPrior& prior) {
  return fit.delta / tau + (prior.enabled ? prior.weight * (1.0 - up_cosine(T, up)) / 2.0 : 0.0);
}

}  // namespace bayesgrasp::vision
