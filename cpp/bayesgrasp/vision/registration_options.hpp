// Options of the registration pipeline, one small struct per step. Every radius and distance is a
// multiple of RegistrationOptions::voxel (defaults for household objects of 5-30 cm: voxel 5 mm,
// normals 2 voxels, FPFH 5 voxels, inlier distance 1.5 voxels, ICP correspondence distance 1.5
// voxels). validate() checks them all; the Registrar calls it once, at construction.
#pragma once

#include <string>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp::vision {

/// Which normal and FPFH estimator prepares the clouds for matching.
enum class FeatureEstimator {
  Ours,  // one fixed-radius grid search per point shared by normals and FPFH, each pair computed once
  Pcl,   // PCL's NormalEstimationOMP + FPFHEstimationOMP (the same definitions)
};

/// Normals and FPFH descriptors (Rusu et al., ICRA 2009).
struct FeatureOptions {
  double normal_radius = 2.0;   // x voxel: PCA neighbourhood of a normal
  double feature_radius = 5.0;  // x voxel: FPFH neighbourhood
  FeatureEstimator estimator = FeatureEstimator::Ours;
};

/// Feature correspondences between the scene and a model.
struct CorrespondenceOptions {
  int neighbours = 2;     // per scene feature: its k nearest model features
  bool reverse = true;    // also each model feature's nearest scene feature
  bool hellinger = true;  // compare sqrt(histograms) (Hellinger distance) instead of raw L2
};

/// The seeded RANSAC over correspondences and the hypotheses it keeps.
struct RansacOptions {
  int iterations = 20000;     // maximum per restart
  int min_iterations = 500;   // per restart, whatever the confidence bound says
  double confidence = 0.999;  // of the adaptive stopping bound
  double edge_similarity = 0.9;                  // pre-rejection: corresponding edge lengths agree to this ratio
  double max_normal_angle = 0.5235987755982988;  // pre-rejection: matched normals agree within this (rad)
  int restarts = 3;     // independent runs (seeds derived from the call's seed and the restart)
  int candidates = 16;  // distinct hypotheses kept per restart (by consensus)
  int hypotheses = 4;   // best candidates over all restarts (by fitting error) refined by a coarse ICP
};

/// Point-to-plane ICP against the model's dense surface samples.
struct IcpOptions {
  double distance = 1.5;     // x voxel: correspondence distance
  int iterations = 30;       // full ICP of the chosen hypothesis
  double tolerance = 1e-5;   // stop when the update is below this (rad / m)
  int coarse_points = 200;   // scene subsample for the coarse ICP of every hypothesis
  int coarse_iterations = 10;
};

/// A model resting on the table keeps its +z (model frame) near `up` (scene frame). With `upright`
/// the RANSAC hypotheses are 4-DOF (yaw about up + translation, from 2 correspondences; ICP then
/// frees all 6 DOF); otherwise 6-DOF (3 correspondences) with tilts beyond max_tilt rejected.
/// enabled = false: 6-DOF, no tilt limit, no up penalty.
struct UpPrior {
  bool enabled = true;
  bool upright = true;
  Vec3 up = Vec3::UnitZ();
  double max_tilt = 1.0471975511965976;  // rad; RANSAC rejects hypotheses tilting the model's up more
  double weight = 1.0;                   // selection cost += weight (1 - cos tilt) / 2
};

struct RegistrationOptions {
  double voxel = 0.005;          // m: downsampling leaf, and the unit of every radius and distance
  double inlier_distance = 1.5;  // x voxel: RANSAC inliers, fitness, RMSE and the cut-off tau of delta
  double weight_sigma = 0.5;     // x voxel: sigma of phi(delta)
  int min_scene_points = 30;     // with normals after downsampling; fewer: TooFewScenePoints
  int model_samples = 0;         // points sampled per model mesh; 0: area / (voxel/3)^2, clamped
  int threads = 0;               // over models and scene features; 0 = all cores (thread_count)
  FeatureOptions features;
  CorrespondenceOptions correspondences;
  RansacOptions ransac;
  IcpOptions icp;
  UpPrior up_prior;
};

/// Each throws std::invalid_argument naming the first bad field, prefixed by `prefix` (the
/// whole struct's validate names them "ransac.iterations: ...").
void validate(const FeatureOptions& o, const std::string& prefix = "");
void validate(const CorrespondenceOptions& o, const std::string& prefix = "");
void validate(const RansacOptions& o, const std::string& prefix = "");
void validate(const IcpOptions& o, const std::string& prefix = "");
void validate(const UpPrior& o, const std::string& prefix = "");
void validate(const RegistrationOptions& options);

}  // namespace bayesgrasp::vision
