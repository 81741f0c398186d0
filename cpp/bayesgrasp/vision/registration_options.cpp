#include "bayesgrasp/vision/registration_options.hpp"

#include <stdexcept>
#include <string>

#include "bayesgrasp/common/checks.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::vision {

void validate(const FeatureOptions& o, const std::string& p) {
  require_positive(o.normal_radius, p + "normal_radius");
  require_positive(o.feature_radius, p + "feature_radius");
  if (o.estimator != FeatureEstimator::Ours && o.estimator != FeatureEstimator::Pcl)
    throw std::invalid_argument(p + "estimator: unknown estimator");
}

void validate(const CorrespondenceOptions& o, const std::string& p) {
  require_at_least(o.neighbours, 1, p + "neighbours");
}

void validate(const RansacOptions& r, const std::string& p) {
  require_at_least(r.iterations, 1, p + "iterations");
  require_at_least(r.min_iterations, 0, p + "min_iterations");
  require_open(r.confidence, 0, 1, p + "confidence");
  require_open(r.edge_similarity, 0, 1, p + "edge_similarity");
  require_positive(r.max_normal_angle, p + "max_normal_angle");
  require_at_least(r.restarts, 1, p + "restarts");
  require_at_least(r.candidates, 1, p + "candidates");
  require_at_least(r.hypotheses, 1, p + "hypotheses");
}

void validate(const IcpOptions& o, const std::string& p) {
  require_positive(o.distance, p + "distance");
  require_at_least(o.iterations, 0, p + "iterations");
  require_non_negative(o.tolerance, p + "tolerance");
  require_at_least(o.coarse_points, 1, p + "coarse_points");
  require_at_least(o.coarse_iterations, 0, p + "coarse_iterations");
}

void validate(const UpPrior& u, const std::string& p) {
  if (!u.up.allFinite()) throw std::invalid_argument(p + "up: must be finite");
  if (u.enabled && !(u.up.norm() > 0)) throw std::invalid_argument(p + "up: must be non-zero");
  require_positive(u.max_tilt, p + "max_tilt");
  require_non_negative(u.weight, p + "weight");
}

constexpr int kMaxModelSamples = 10000000;

void validate(const RegistrationOptions& o) {
  require_positive(o.voxel, "voxel");
  require_positive(o.inlier_distance, "inlier_distance");
  require_positive(o.weight_sigma, "weight_sigma");
  require_at_least(o.min_scene_points, 1, "min_scene_points");
  require_at_least(o.model_samples, 0, "model_samples");
  // 10^7 points and normals are 480 MB; more would only exhaust memory (the default is <= 200000).
  if (o.model_samples > kMaxModelSamples)
    throw std::invalid_argument("model_samples: at most " + std::to_string(kMaxModelSamples) + ", got " +
                                std::to_string(o.model_samples));
  thread_count(o.threads, "threads");
  validate(o.features, "features.");
  validate(o.correspondences, "correspondences.");
  validate(o.ransac, "ransac.");
  validate(o.icp, "icp.");
  validate(o.up_prior, "up_prior.");
}

}  // namespace bayesgrasp::vision
