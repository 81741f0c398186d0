#include "bayesgrasp/vision/registration_options.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::vision {

namespace {
std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void positive(double v, const char* name) {
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + ": must be positive and finite, got " + str(v));
}

void at_least(long long v, long long lo, const char* name) {
  if (v < lo)
    throw std::invalid_argument(std::string(name) + ": must be >= " + std::to_string(lo) + ", got " +
                                std::to_string(v));
}

void open_unit(double v, const char* name) {
  if (!(v > 0 && v < 1)) throw std::invalid_argument(std::string(name) + ": must be in (0, 1), got " + str(v));
}

void non_negative(double v, const char* name) {
  if (!(v >= 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + ": must be finite and >= 0, got " + str(v));
}

void validate_steps(const RegistrationOptions& o) {
  positive(o.features.normal_radius, "features.normal_radius");
  positive(o.features.feature_radius, "features.feature_radius");
  if (o.features.estimator != FeatureEstimator::Ours && o.features.estimator != FeatureEstimator::Pcl)
    throw std::invalid_argument("features.estimator: unknown estimator");
  at_least(o.correspondences.neighbours, 1, "correspondences.neighbours");
  const RansacOptions& r = o.ransac;
  at_least(r.iterations, 1, "ransac.iterations");
  at_least(r.min_iterations, 0, "ransac.min_iterations");
  open_unit(r.confidence, "ransac.confidence");
  open_unit(r.edge_similarity, "ransac.edge_similarity");
  positive(r.max_normal_angle, "ransac.max_normal_angle");
  at_least(r.restarts, 1, "ransac.restarts");
  at_least(r.candidates, 1, "ransac.candidates");
  at_least(r.hypotheses, 1, "ransac.hypotheses");
  positive(o.icp.distance, "icp.distance");
  at_least(o.icp.iterations, 0, "icp.iterations");
  non_negative(o.icp.tolerance, "icp.tolerance");
  at_least(o.icp.coarse_points, 1, "icp.coarse_points");
  at_least(o.icp.coarse_iterations, 0, "icp.coarse_iterations");
  const UpPrior& u = o.up_prior;
  if (!u.up.allFinite()) throw std::invalid_argument("up_prior.up: must be finite");
  if (u.enabled && !(u.up.norm() > 0)) throw std::invalid_argument("up_prior.up: must be non-zero");
  positive(u.max_tilt, "up_prior.max_tilt");
  non_negative(u.weight, "up_prior.weight");
}
}  // namespace

constexpr int kMaxModelSamples = 10000000;

void validate(const RegistrationOptions& o) {
  positive(o.voxel, "voxel");
  positive(o.inlier_distance, "inlier_distance");
  positive(o.weight_sigma, "weight_sigma");
  at_least(o.min_scene_points, 1, "min_scene_points");
  at_least(o.model_samples, 0, "model_samples");
  // 10^7 points and normals are 480 MB; more would only exhaust memory (the default is <= 200000).
  if (o.model_samples > kMaxModelSamples)
    throw std::invalid_argument("model_samples: at most " + std::to_string(kMaxModelSamples) + ", got " +
                                std::to_string(o.model_samples));
  thread_count(o.threads, "threads");
  validate_steps(o);
}

}  // namespace bayesgrasp::vision
