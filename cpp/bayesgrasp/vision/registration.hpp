// Registration of a partial scene cloud against N object models: voxel downsampling (PCL),
// normals and FPFH features (ours, or PCL's with pcl_features), a seeded feature-correspondence
// RANSAC with edge-length pre-rejection and an optional up-axis prior, several restarts and
// hypotheses, point-to-plane ICP refinement, and a hypothesis choice by fitting error plus an
// upside-down penalty. A Registrar prepares the models once and registers any number of scenes
// against them; register_models is one-shot.
// PCL is used in registration.cpp only; this header is plain Eigen.
//
// Every radius and threshold is a multiple of one voxel size (defaults for household objects of
// 5-30 cm: voxel 5 mm, normals 2 voxels, FPFH 5 voxels, RANSAC inlier distance 1.5 voxels,
// ICP correspondence distance 1.5 voxels).
//
// Fitting error and weight (the thesis's delta_i and phi(delta_i), Eq. 4.1):
//   delta = sqrt(mean_i min(d_i, tau)^2)  over the downsampled scene points, d_i the distance to
//           the registered model's surface samples, tau = inlier distance (so missing parts and
//           outliers count as tau, and a good fit with noise alone gives delta ~ noise);
//   phi   = exp(-delta^2 / (2 sigma^2)), sigma = weight_sigma (default 0.5 voxel), unnormalised;
//   weight = phi / sum_j phi_j over the successful models of the call (0 for failures).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bayesgrasp/vision/camera.hpp"

namespace bayesgrasp::vision {

/// Points and unit outward normals sampled on a surface.
struct SurfaceSamples {
  Points points;
  Points normals;
};

/// Total surface area of a mesh.
double surface_area(const TriMesh& mesh);

/// n points sampled uniformly on the surface (area-weighted triangle choice, uniform barycentric
/// coordinates), with the faces' unit normals. Seeded. Throws if the mesh is invalid or has no area.
SurfaceSamples sample_surface(const TriMesh& mesh, int n, std::uint64_t seed);

struct RegistrationParams {
  double voxel = 0.005;
  double normal_radius = 2.0;      // x voxel
  double feature_radius = 5.0;     // x voxel
  double inlier_distance = 1.5;    // x voxel: RANSAC inliers, fitness, RMSE, tau of delta
  double icp_distance = 1.5;       // x voxel: ICP correspondence distance
  int ransac_iterations = 20000;   // maximum per restart
  int ransac_min_iterations = 500; // per restart, whatever the confidence bound says
  double ransac_confidence = 0.999;
  double edge_similarity = 0.9;    // pre-rejection: corresponding edge lengths agree to this ratio
  double max_normal_angle = 0.5235987755982988;  // pre-rejection: matched normals agree within this (rad)
  int feature_neighbours = 2;      // correspondences per scene point: its k nearest model features
  bool reverse_matches = true;     // also each model feature's nearest scene feature
  bool pcl_features = false;       // PCL's NormalEstimationOMP + FPFHEstimationOMP instead of ours
                                   // (same definitions; ours shares one neighbour search and computes
                                   // each pair once, about 3x faster)
  bool hellinger = true;           // compare sqrt(histograms) (Hellinger distance) instead of raw L2
  int restarts = 3;                // independent RANSAC runs (seeds seed, seed+1, ...)
  int candidates = 16;             // distinct hypotheses kept per restart (by consensus), then ranked
                                   // by fitting error on a scene subsample
  int hypotheses = 4;              // best candidates (over all restarts) refined by a coarse ICP
  int coarse_points = 200;         // scene subsample for the coarse ICP of every hypothesis
  int coarse_icp_iterations = 10;
  int icp_iterations = 30;         // full ICP of the chosen hypothesis
  double icp_tolerance = 1e-5;     // stop when the update is below this (rad / m)
  // Up prior: a model resting on the table keeps its +z (model frame) near `up` (scene frame).
  // With `upright` the RANSAC hypotheses are 4-DOF (yaw about up + translation, from 2
  // correspondences; ICP then frees all 6 DOF); otherwise 6-DOF (3 correspondences) with tilts
  // beyond max_tilt rejected. use_up_prior = false: 6-DOF, no tilt limit, no up penalty.
  bool use_up_prior = true;
  bool upright = true;
  Vec3 up = Vec3::UnitZ();
  double max_tilt = 1.0471975511965976;  // rad; RANSAC rejects hypotheses tilting the model's up more
  double up_weight = 1.0;          // selection cost += up_weight (1 - cos tilt) / 2
  double weight_sigma = 0.5;       // x voxel, sigma of phi(delta)
  int min_scene_points = 30;       // after downsampling; fewer -> success = false
  int model_samples = 0;           // points sampled per model mesh; 0: area / (voxel/3)^2, clamped
  bool has_viewpoint = false;      // scene normals point towards this (e.g. the camera centre);
  Vec3 viewpoint = Vec3::Zero();   // without one they point away from the scene centroid
  std::uint64_t seed = 0;
  int threads = 0;                 // OpenMP threads over models (0: OpenMP's default)
};

struct RegistrationResult {
  bool success = false;
  std::string reason;                             // why not, when success is false
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // model frame -> scene frame
  double fitness = 0.0;   // fraction of downsampled scene points within the inlier distance
  double rmse = 0.0;      // RMS distance of those inliers, m
  double delta = 0.0;     // fitting error (see above), m
  double phi = 0.0;       // exp(-delta^2 / 2 sigma^2)
  double weight = 0.0;    // phi normalised over the successful models of the call
  double up_cos = 1.0;    // cosine between the model's +z mapped to the scene and `up`
  double cost = 0.0;      // selection cost of the chosen hypothesis
  int scene_points = 0;   // after downsampling
  int model_points = 0;   // after downsampling
  int ransac_iterations = 0;  // total over restarts
  double time_features = 0.0, time_global = 0.0, time_icp = 0.0;  // s (per scene; register_models
                                                                  // adds the model preparation)
};

/// A model: its mesh's surface samples (or any points with outward normals). The samples are
/// used densely for the fit measures and voxel-downsampled for features and ICP.
struct ModelCloud {
  SurfaceSamples surface;
};

/// Samples a mesh for registration (see RegistrationParams::model_samples). Throws
/// std::invalid_argument if the mesh is invalid or has no area.
ModelCloud model_from_mesh(const TriMesh& mesh, const RegistrationParams& params, std::uint64_t seed);

/// Models prepared once, scenes registered against them any number of times.
///
/// Preparing a model (a neighbour grid over its dense samples, voxel downsampling, normals, FPFH features and
/// their transformed copies for matching) is the costliest part of a one-shot registration and
/// does not depend on the scene, so a Registrar does it once per model in add_models() and
/// register_scene() does only the per-scene work: the scene's features, the feature matching,
/// RANSAC and ICP. The parameters (voxel, radii, thresholds, up prior, ...) are fixed at
/// construction; the seed, the viewpoint and the subset of models are given per call. With the
/// same parameters, seed and viewpoint, register_scene() gives exactly the result of
/// register_models() (which builds a one-shot Registrar), apart from the timings.
///
/// register_scene() is const and may be called from several threads at once.
class Registrar {
 public:
  /// Throws std::invalid_argument for bad parameters (see register_models).
  explicit Registrar(const RegistrationParams& params = {});
  ~Registrar();
  Registrar(Registrar&&) noexcept;
  Registrar& operator=(Registrar&&) noexcept;
  Registrar(const Registrar&) = delete;
  Registrar& operator=(const Registrar&) = delete;

  /// Prepares the models (in parallel over models, params.threads) and appends them; returns the
  /// index of the first. A model without surface points, with non-finite values or too few
  /// points after downsampling is kept, marked as failed with a reason that every registration
  /// against it reports.
  int add_models(const std::vector<ModelCloud>& models);

  int size() const;
  const RegistrationParams& params() const;
  bool model_ok(int i) const;                   // prepared successfully
  const std::string& model_reason(int i) const; // why not
  int model_points(int i) const;                // after downsampling
  double model_time(int i) const;               // s spent preparing it

  /// Registers the scene cloud (N x 3; NaN rows dropped) against the models with the given
  /// indices (empty: all, in order), parallel over models. Returns one result per model asked for;
  /// the weights are normalised over those. Throws std::invalid_argument for an empty scene, no
  /// models or an index out of range; per-model problems give success = false with a reason.
  std::vector<RegistrationResult> register_scene(const Points& scene, std::uint64_t seed,
                                                 const std::optional<Vec3>& viewpoint = std::nullopt,
                                                 const std::vector<int>& models = {}) const;

 private:
  struct Model;
  struct Impl;
  const Model& model(int i) const;  // prepared model i, index checked
  std::unique_ptr<Impl> impl_;
};

/// Registers the scene cloud (N x 3; NaN rows are dropped) against every model: a one-shot
/// Registrar (params.seed, params.viewpoint if params.has_viewpoint). Parallel over models
/// (OpenMP). Throws std::invalid_argument for an empty scene, no models or bad parameters;
/// per-model problems (too few points, no surface, no hypothesis) give success = false with a
/// reason. time_features includes the model's preparation.
std::vector<RegistrationResult> register_models(const Points& scene, const std::vector<ModelCloud>& models,
                                                const RegistrationParams& params = {});

/// Rotation angle (rad) between two rotations; with `axis` non-zero, rotation about that axis
/// (model frame) is ignored: the angle between R_a axis and R_b axis (bodies of revolution).
double rotation_error(const Mat3& Ra, const Mat3& Rb, const Vec3& axis = Vec3::Zero());

}  // namespace bayesgrasp::vision
