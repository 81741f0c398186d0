// The registration pipeline's stages: a model prepared once (dense samples and their grid,
// downsampled points, normals and descriptors), a scene prepared once per call, and the
// registration of one prepared model against the prepared scene.
#pragma once

#include <cstdint>
#include <optional>

#include "bayesgrasp/vision/correspondences.hpp"
#include "bayesgrasp/vision/fit.hpp"
#include "bayesgrasp/vision/ransac.hpp"
#include "bayesgrasp/vision/registration.hpp"

namespace bayesgrasp::vision {

struct PreparedModel {
  PreparedModelInfo info;
  DenseModel dense;                // all surface samples with exact normals
  OrientedPointsD points;          // downsampled, with oriented normals
  MatchDescriptors descriptors;    // one per downsampled point
};

struct PreparedScene {
  OrientedPointsD points;        // downsampled, with normals
  MatchDescriptors descriptors;  // one per downsampled point
  double time = 0.0;             // s spent preparing it
  int size() const { return points.size(); }
};

/// Downsampling, normals along the samples' normals, descriptors; the dense grid over the samples
/// has the radius max(inlier, ICP distance). A model that cannot be prepared gets a failed status.
PreparedModel prepare_model(const SurfaceSamples& samples, const RegistrationOptions& options);

/// Downsampling, normals towards the viewpoint (or away from the centroid), descriptors.
PreparedScene prepare_scene(const OrientedCloud& scene, const RegistrationOptions& options,
                            const std::optional<Vec3>& viewpoint, int threads);

/// Registers one prepared model (info.ok()) against the prepared scene.
RegistrationResult register_prepared(const PreparedModel& model, const PreparedScene& scene,
                                     const RegistrationOptions& options, std::uint64_t seed);

}  // namespace bayesgrasp::vision
