// The seeded RANSAC over feature correspondences: minimal samples (2 correspondences for the
// 4-DOF upright hypotheses, 3 for 6-DOF), pre-rejection by edge lengths and normals, consensus
// over all correspondences, an adaptive stopping bound, several restarts, and per restart the
// best distinct hypotheses.
#pragma once

#include <cstdint>
#include <vector>

#include "bayesgrasp/vision/correspondences.hpp"
#include "bayesgrasp/vision/step_context.hpp"

namespace bayesgrasp::vision {

struct Hypothesis {
  Iso3 T = Iso3::Identity();  // scene -> model
  int inliers = 0;            // consensus: correspondences within the inlier distance
  double cost = 0.0;          // fitting error when ranked (hypotheses.hpp)
};

/// Two transforms are the same hypothesis when they differ by less than 4 voxels in translation
/// and 20 degrees in rotation.
bool same_hypothesis(const Iso3& a, const Iso3& b, double voxel);

/// Rigid transform (no scale) taking the src points onto the dst points in the least-squares sense.
Iso3 kabsch(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst);

/// Points with normals, in double precision, as RANSAC and ICP use them.
struct OrientedPointsD {
  std::vector<Eigen::Vector3d> points, normals;
  int size() const { return static_cast<int>(points.size()); }
};

struct RansacResult {
  std::vector<Hypothesis> hypotheses;  // the distinct ones of every restart, restart by restart
  int iterations = 0;                  // total over restarts
};

/// options.ransac.restarts runs, run r seeded with mix_seed(seed * 0x100000001B3 + r).
RansacResult ransac(const OrientedPointsD& scene, const OrientedPointsD& model, const Correspondences& corr,
                    const StepContext& context, std::uint64_t seed);

}  // namespace bayesgrasp::vision
