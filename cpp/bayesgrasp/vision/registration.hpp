// Registration of a partial scene cloud against N object models (thesis §4.2, Pub. V):
//   1. voxel downsampling (PCL), normals and FPFH features (features.hpp: ours or PCL's);
//   2. feature correspondences (correspondences.hpp);
//   3. a seeded RANSAC over them with edge-length pre-rejection and an optional up-axis prior,
//      several restarts, distinct hypotheses (ransac.hpp);
//   4. the best hypotheses by fitting error, each refined by a coarse ICP, the winner chosen by
//      fitting error plus an upside-down penalty (hypotheses.hpp);
//   5. point-to-plane ICP against the model's dense surface samples (icp.hpp);
//   6. the fit measures delta_i and phi(delta_i) of Eq. 4.1 (fit.hpp).
// A Registrar prepares the models once (registrar.cpp) and registers any number of scenes against
// them; register_models is one-shot. This header is plain Eigen (PCL stays in the .cpp files).
//
// Fitting error and weight (the thesis's delta_i and phi(delta_i), Eq. 4.1):
//   delta = sqrt(mean_i min(d_i, tau)^2)  over the downsampled scene points, d_i the distance to
//           the registered model's surface samples, tau = inlier distance (so missing parts and
//           outliers count as tau, and a good fit with noise alone gives delta ~ noise);
//   phi   = exp(-delta^2 / (2 sigma^2)), sigma = weight_sigma voxels, unnormalised.
// Normalising phi over the models is the belief's job (Python: bayesgrasp.belief.shape_weights).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bayesgrasp/geometry/surface_sampling.hpp"
#include "bayesgrasp/vision/registration_options.hpp"

namespace bayesgrasp::vision {

/// Why a model did or did not register.
enum class RegistrationStatus {
  Ok,
  NoSurface,           // the model has no surface points
  InvalidModel,        // its points or normals are not finite
  TooFewModelPoints,   // fewer than 3 model points with normals after downsampling
  TooFewScenePoints,   // fewer than min_scene_points scene points with normals after downsampling
  NoHypothesis,        // RANSAC found no transform (too few consistent feature matches)
  NonFiniteTransform,  // the refinement diverged
};

struct RegistrationResult {
  RegistrationStatus status = RegistrationStatus::NoHypothesis;
  std::string reason;  // human-readable, when status is not Ok
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  // model frame -> scene frame
  double fitness = 0.0;  // fraction of downsampled scene points within the inlier distance
  double rmse = 0.0;     // RMS distance of those inliers, m
  double delta = 0.0;    // fitting error delta_i (see above), m
  double phi = 0.0;      // phi(delta_i) = exp(-delta^2 / 2 sigma^2)
  double up_cos = 1.0;   // cosine between the model's +z mapped to the scene and `up`
  double cost = 0.0;     // selection cost of the chosen hypothesis
  int scene_points = 0;  // after downsampling
  int model_points = 0;  // after downsampling
  int ransac_iterations = 0;  // total over restarts
  double time_features = 0.0, time_global = 0.0, time_icp = 0.0;  // s (per scene; register_models
                                                                  // adds the model preparation)
  bool success() const { return status == RegistrationStatus::Ok; }
};

/// A model: its mesh's surface samples (or any points with outward normals). The samples are
/// used densely for the fit measures and ICP, and voxel-downsampled for features and RANSAC.
struct ModelCloud {
  SurfaceSamples surface;
};

/// Samples a mesh for registration: options.model_samples points (0: area / (voxel/3)^2, clamped
/// to [2000, 200000]). Throws std::invalid_argument for bad options, an invalid mesh or one
/// without area.
ModelCloud model_from_mesh(const TriMesh& mesh, const RegistrationOptions& options, std::uint64_t seed);

/// A prepared model's state.
struct PreparedModelInfo {
  RegistrationStatus status = RegistrationStatus::Ok;  // Ok, NoSurface, InvalidModel or TooFewModelPoints
  std::string reason;  // when status is not Ok
  int points = 0;      // after downsampling
  double time = 0.0;   // s spent preparing it
  bool ok() const { return status == RegistrationStatus::Ok; }
};

/// Models prepared once, scenes registered against them any number of times.
///
/// Preparing a model (a radius grid over its dense samples, voxel downsampling, normals, FPFH
/// features) does not depend on the scene, so a Registrar does it once per model in add_models()
/// and register_scene() does only the per-scene work: the scene's features, the matching, RANSAC
/// and ICP. The options are fixed at construction; the seed, the viewpoint and the subset of models
/// are given per call. With the same options, seed and viewpoint, register_scene() gives exactly
/// the result of register_models() (a one-shot Registrar), apart from the timings.
///
/// register_scene() is const and may be called from several threads at once.
class Registrar {
 public:
  /// Throws std::invalid_argument for bad options (validate()).
  explicit Registrar(const RegistrationOptions& options = {});
  ~Registrar();
  Registrar(Registrar&&) noexcept;
  Registrar& operator=(Registrar&&) noexcept;
  Registrar(const Registrar&) = delete;
  Registrar& operator=(const Registrar&) = delete;

  /// Prepares the models (in parallel over models) and appends them; returns the index of the
  /// first. A model without surface points, with non-finite values or too few points after
  /// downsampling is kept, with a failed status that every registration against it reports.
  int add_models(const std::vector<ModelCloud>& models);

  int size() const;
  const RegistrationOptions& options() const;
  /// Model i's preparation; throws std::invalid_argument if i is out of range.
  PreparedModelInfo model_info(int i) const;

  /// Registers the scene cloud (N x 3; rows with NaN dropped) against every model, in parallel
  /// over models; one result per model. `viewpoint`: the camera centre (scene normals point
  /// towards it; without one they point away from the scene's centroid). Throws
  /// std::invalid_argument for a scene without finite points, a non-finite viewpoint or a
  /// registrar without models; per-model problems give a result with a failed status.
  std::vector<RegistrationResult> register_scene(const Points& scene, std::uint64_t seed,
                                                 const std::optional<Vec3>& viewpoint = std::nullopt) const;
  /// The same against the models with the given indices (in that order; not empty, each in range).
  std::vector<RegistrationResult> register_scene(const Points& scene, std::uint64_t seed,
                                                 const std::optional<Vec3>& viewpoint,
                                                 const std::vector<int>& models) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Registers the scene against every model with a one-shot Registrar (register_scene's
/// arguments); time_features includes each model's preparation. Throws std::invalid_argument for
/// bad options, no models or a scene without finite points (checked before any model is prepared).
std::vector<RegistrationResult> register_models(const Points& scene, const std::vector<ModelCloud>& models,
                                                const RegistrationOptions& options = {}, std::uint64_t seed = 0,
                                                const std::optional<Vec3>& viewpoint = std::nullopt);

/// Rotation angle (rad) between two rotations; with `axis` non-zero, rotation about that axis
/// (model frame) is ignored: the angle between R_a axis and R_b axis (bodies of revolution).
double rotation_error(const Mat3& Ra, const Mat3& Rb, const Vec3& axis = Vec3::Zero());

}  // namespace bayesgrasp::vision
