// Fixed-radius neighbour search among fixed points: a uniform grid with cells of at least the
// radius over the points' bounding box, points sorted by cell (counting sort). A query scans the
// 3 x 3 x 3 cells around its own. Used wherever the registration needs neighbours within a known
// distance: the normal and FPFH neighbourhoods, and the nearest dense model sample of the fit
// measures and ICP, whose distances are all cut off at the inlier / ICP distance.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace bayesgrasp::vision {

using PointsF = std::vector<Eigen::Vector3f>;

class RadiusGrid {
 public:
  RadiusGrid() = default;
  RadiusGrid(const PointsF& points, double radius) { build(points, radius); }
  void build(const PointsF& points, double radius);

  /// Indices of all points within the radius of q (distance <= radius), in cell order.
  void within(const Eigen::Vector3d& q, std::vector<int>& out) const;

  /// Index of the nearest point within the radius of q (ties: the first in cell order), -1 if none.
  int nearest(const Eigen::Vector3d& q) const;

 private:
  std::size_t cell_of(const Eigen::Vector3d& p) const;
  std::size_t cell_index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * n_[1] + y) * n_[0] + x;
  }
  // Squared distances from q to the points of one cell: the nearest below `best` updates best/arg.
  void scan_nearest(std::size_t cell, float qx, float qy, float qz, float& best, int& arg) const;

  double h_ = 1.0, r2_ = 0.0;  // cell size, squared radius
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  int n_[3] = {1, 1, 1};    // cells per axis
  std::vector<int> start_;  // points of cell c: [start_[c], start_[c+1]) in xyz_ / ids_
  std::vector<float> xyz_;
  std::vector<int> ids_;
};

}  // namespace bayesgrasp::vision
