// Table-top segmentation (the planar supporting-surface heuristic): the dominant plane by
// RANSAC, the points above it, and Euclidean clusters of those, largest first.
// PCL is used in segmentation.cpp only; this header is plain Eigen.
#pragma once

#include <string>
#include <vector>

#include "bayesgrasp/vision/camera.hpp"

namespace bayesgrasp::vision {

struct SegmentationOptions {
  double plane_threshold = 0.006;   // m, RANSAC inlier distance of the table plane
  int plane_iterations = 1000;      // RANSAC iterations (PCL's SACSegmentation, fixed internal seed)
  double min_height = 0.008;        // m, points kept must be at least this far above the plane
  double max_height = 1.0;          // m, ... and at most this far
  double cluster_tolerance = 0.01;  // m, Euclidean clustering distance
  int min_cluster_size = 50;
  int max_cluster_size = 1000000;
  Vec3 up = Vec3::UnitZ();          // the plane normal is oriented to have a positive dot with this
                                    // (use the world z axis for world-frame clouds)
};

struct SegmentationResult {
  Eigen::Vector4d plane = Eigen::Vector4d::Zero();  // n.x, n.y, n.z, d with n.p + d = 0, n unit, n.up > 0
  std::vector<int> plane_inliers;                     // row indices into the input cloud
  std::vector<std::vector<int>> clusters;             // row indices, largest cluster first
  std::vector<Points> cluster_points;                 // the clusters' points
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const SegmentationOptions& options);

/// Segments an (N, 3) cloud. Rows with NaN are ignored (an organised cloud can be passed as is).
/// Throws std::invalid_argument if the options are bad (validate), fewer than 3 finite points
/// remain or no plane is found.
SegmentationResult segment_table(const Points& cloud, const SegmentationOptions& options = {});

}  // namespace bayesgrasp::vision
