// Points with normals in single precision, the registration's working clouds.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "bayesgrasp/geometry/surface_sampling.hpp"
#include "bayesgrasp/vision/radius_grid.hpp"

namespace bayesgrasp::vision {

/// normals[i] belongs to points[i]. Before feature estimation the normals are reference normals
/// (a model's surface normals, averaged per voxel) or zero (a scene); after it, estimated and
/// oriented.
struct OrientedCloud {
  PointsF points;
  PointsF normals;
  int size() const { return static_cast<int>(points.size()); }
};

/// The rows of P with finite coordinates, with zero normals.
OrientedCloud finite_points(const Points& P);

/// The rows of S.points with finite coordinates and their normals.
OrientedCloud finite_points(const SurfaceSamples& S);

/// PCL's voxel grid: one point per occupied voxel of side `voxel`, the average of its points and
/// of their normals, in the grid's order.
OrientedCloud voxel_downsample(const OrientedCloud& cloud, double voxel);

/// The points in double precision.
std::vector<Eigen::Vector3d> to_double(const PointsF& points);

}  // namespace bayesgrasp::vision
