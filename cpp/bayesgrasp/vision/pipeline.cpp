#include "bayesgrasp/vision/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "bayesgrasp/vision/hypotheses.hpp"
#include "bayesgrasp/vision/icp.hpp"

namespace bayesgrasp::vision {

namespace {
class Stopwatch {
 public:
  double seconds() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }
  void restart() { t0_ = Clock::now(); }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point t0_ = Clock::now();
};

OrientedPointsD in_double(const OrientedCloud& c) { return {to_double(c.points), to_double(c.normals)}; }

NormalOrientation scene_orientation(const std::optional<Vec3>& viewpoint) {
  return viewpoint ? NormalOrientation::towards(*viewpoint) : NormalOrientation::away_from_centroid();
}

RegistrationResult& fail(RegistrationResult& res, RegistrationStatus status, std::string reason) {
  res.status = status;
  res.reason = std::move(reason);
  return res;
}
}  // namespace

PreparedModel prepare_model(const SurfaceSamples& S, const RegistrationOptions& o) {
  const Stopwatch clock;
  PreparedModel m;
  PreparedModelInfo& info = m.info;
  if (S.points.rows() == 0 || S.points.rows() != S.normals.rows()) {
    info.status = RegistrationStatus::NoSurface;
    info.reason = "model has no surface points";
    return m;
  }
  if (!S.points.allFinite() || !S.normals.allFinite()) {
    info.status = RegistrationStatus::InvalidModel;
    info.reason = "model points or normals contain NaN or infinity";
    return m;
  }
  m.dense.samples = finite_points(S);
  m.dense.grid.build(m.dense.samples.points, std::max(o.inlier_distance, o.icp.distance) * o.voxel);
  const FeatureCloud fc = estimate_features(voxel_downsample(m.dense.samples, o.voxel), o.features, o.voxel,
                                            NormalOrientation::along_reference(), 1);
  info.points = fc.cloud.size();
  if (info.points < 3) {
    info.status = RegistrationStatus::TooFewModelPoints;
    info.reason = "model has too few points after downsampling (" + std::to_string(info.points) + ")";
  } else {
    m.points = in_double(fc.cloud);
    m.descriptors = match_descriptors(fc.features, o.correspondences.hellinger);
  }
  info.time = clock.seconds();
  return m;
}

PreparedScene prepare_scene(const OrientedCloud& scene, const RegistrationOptions& o,
                            const std::optional<Vec3>& viewpoint, int threads) {
  const Stopwatch clock;
  const FeatureCloud fc = estimate_features(voxel_downsample(scene, o.voxel), o.features, o.voxel,
                                            scene_orientation(viewpoint), threads);
  PreparedScene s;
  s.points = in_double(fc.cloud);
  s.descriptors = match_descriptors(fc.features, o.correspondences.hellinger);
  s.time = clock.seconds();
  return s;
}

RegistrationResult register_prepared(const PreparedModel& model, const PreparedScene& scene,
                                     const RegistrationOptions& o, std::uint64_t seed) {
  RegistrationResult res;
  res.scene_points = scene.size();
  res.model_points = model.info.points;
  res.time_features = scene.time;
  const StepContext c(o);
  const double voxel = c.voxel, tau = c.tau;
  // Global registration: feature correspondences, then RANSAC over them (several restarts).
  Stopwatch clock;
  const Correspondences corr = correspondences(scene.descriptors, model.descriptors, o.correspondences);
  const RansacResult global = ransac(scene.points, model.points, corr, c, seed);
  res.ransac_iterations = global.iterations;
  res.time_global = clock.seconds();
  if (global.hypotheses.empty())
    return fail(res, RegistrationStatus::NoHypothesis,
                "no transform hypothesis found (too few consistent feature matches)");
  // Local refinement: the best distinct hypotheses by fitting error on a scene subsample, each
  // refined by a coarse ICP; the winner by fitting error + up penalty, then a full ICP.
  clock.restart();
  const std::vector<Eigen::Vector3d> sub = subsample(scene.points.points, o.icp.coarse_points);
  const std::vector<Hypothesis> ranked = rank_hypotheses(global.hypotheses, model.dense, sub, c);
  const Iso3 coarse = choose_hypothesis(ranked, model.dense, sub, c);
  const Iso3 T = point_to_plane_icp(model.dense, scene.points.points, coarse, o.icp.distance * voxel,
                                    o.icp.iterations, o.icp.tolerance);
  // Fit measures: delta_i and phi(delta_i) of Eq. 4.1.
  const Fit f = measure_fit(model.dense, scene.points.points, T, tau);
  res.transform = T.inverse().matrix();
  res.fitness = f.fitness;
  res.rmse = f.rmse;
  res.delta = f.delta;
  res.phi = phi(f.delta, o.weight_sigma * voxel);
  res.up_cos = up_cosine(T, c.up);
  res.cost = selection_cost(f, T, tau, c.up, o.up_prior);
  res.time_icp = clock.seconds();
  if (!res.transform.allFinite()) {
    res.transform.setIdentity();
    return fail(res, RegistrationStatus::NonFiniteTransform, "registration produced a non-finite transform");
  }
  res.status = RegistrationStatus::Ok;
  return res;
}

}  // namespace bayesgrasp::vision
