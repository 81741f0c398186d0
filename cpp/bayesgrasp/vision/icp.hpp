// Point-to-plane ICP of scene points against a model's dense surface samples and their exact
// normals.
#pragma once

#include <vector>

#include "bayesgrasp/vision/fit.hpp"

namespace bayesgrasp::vision {

/// Refines T (scene -> model): each iteration pairs every scene point with its nearest dense
/// sample within max_distance (m) and solves the linearised point-to-plane least squares
/// min sum_i ((R p_i + t - s_i) . n_i)^2 for a small rotation and translation; stops after
/// `iterations`, when fewer than 6 pairs remain, or when the update is below `tolerance` (rad, m).
Iso3 point_to_plane_icp(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, Iso3 T,
                        double max_distance, int iterations, double tolerance);

}  // namespace bayesgrasp::vision
