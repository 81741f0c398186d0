#include "bayesgrasp/vision/radius_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bayesgrasp::vision {

void RadiusGrid::build(const PointsF& points, double radius) {
  r2_ = radius * radius;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  // Cell size: the radius, larger if the grid would have more than kMaxCells cells.
  constexpr double kMaxCells = 4.0e6;
  const Eigen::Vector3d ext = (hi - lo).cwiseMax(radius);
  h_ = std::max(radius, std::cbrt(ext.prod() / kMaxCells));
  origin_ = lo;
  for (int a = 0; a < 3; ++a) n_[a] = static_cast<int>(std::floor(ext[a] / h_)) + 1;
  const std::size_t cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  start_.assign(cells + 1, 0);
  std::vector<std::size_t> key(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    key[i] = cell_of(points[i].cast<double>());
    ++start_[key[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  xyz_.resize(3 * points.size());
  ids_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int j = fill[key[i]]++;
    ids_[j] = static_cast<int>(i);
    for (int a = 0; a < 3; ++a) xyz_[3 * j + a] = points[i][a];
  }
}

void RadiusGrid::within(const Eigen::Vector3d& q, std::vector<int>& out) const {
  out.clear();
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const double fl = std::floor((q[a] - origin_[a]) / h_);
    if (!(fl >= -1 && fl <= n_[a])) return;
    c[a] = static_cast<int>(fl);
  }
  const float qx = static_cast<float>(q.x()), qy = static_cast<float>(q.y()), qz = static_cast<float>(q.z());
  const float r2 = static_cast<float>(r2_);
  for (int z = std::max(0, c[2] - 1); z <= std::min(n_[2] - 1, c[2] + 1); ++z)
    for (int y = std::max(0, c[1] - 1); y <= std::min(n_[1] - 1, c[1] + 1); ++y)
      for (int x = std::max(0, c[0] - 1); x <= std::min(n_[0] - 1, c[0] + 1); ++x) {
        const std::size_t cell = cell_index(x, y, z);
        for (int j = start_[cell], e = start_[cell + 1]; j < e; ++j) {
          const float dx = xyz_[3 * j] - qx, dy = xyz_[3 * j + 1] - qy, dz = xyz_[3 * j + 2] - qz;
          if (dx * dx + dy * dy + dz * dz <= r2) out.push_back(ids_[j]);
        }
      }
}

void RadiusGrid::scan_nearest(std::size_t cell, float qx, float qy, float qz, float& best, int& arg) const {
  for (int j = start_[cell], e = start_[cell + 1]; j < e; ++j) {
    const float dx = xyz_[3 * j] - qx, dy = xyz_[3 * j + 1] - qy, dz = xyz_[3 * j + 2] - qz;
    const float d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < best) {
      best = d2;
      arg = ids_[j];
    }
  }
}

int RadiusGrid::nearest(const Eigen::Vector3d& q) const {
  int c[3];
  Eigen::Vector3d f;  // q's position inside its cell, in [0, 1) per axis when inside the grid
  for (int a = 0; a < 3; ++a) {
    const double u = (q[a] - origin_[a]) / h_;
    const double fl = std::floor(u);
    if (!(fl >= -1 && fl <= n_[a])) return -1;  // farther than one cell outside the grid (or NaN)
    c[a] = static_cast<int>(fl);
    f[a] = u - fl;
  }
  float best = static_cast<float>(r2_);
  int arg = -1;
  const float qx = static_cast<float>(q.x()), qy = static_cast<float>(q.y()), qz = static_cast<float>(q.z());
  // Own cell first, then the others ordered by how far their box is; a cell whose box is farther
  // than the best distance so far is skipped.
  static constexpr int kOrder[27][3] = {
      {0, 0, 0},   {-1, 0, 0},  {1, 0, 0},   {0, -1, 0},  {0, 1, 0},   {0, 0, -1},   {0, 0, 1},
      {-1, -1, 0}, {-1, 1, 0},  {1, -1, 0},  {1, 1, 0},   {-1, 0, -1}, {-1, 0, 1},   {1, 0, -1},
      {1, 0, 1},   {0, -1, -1}, {0, -1, 1},  {0, 1, -1},  {0, 1, 1},   {-1, -1, -1}, {-1, -1, 1},
      {-1, 1, -1}, {-1, 1, 1},  {1, -1, -1}, {1, -1, 1},  {1, 1, -1},  {1, 1, 1}};
  for (const auto& o : kOrder) {
    double box2 = 0;  // squared distance from q to the neighbour cell's box
    bool inside = true;
    for (int a = 0; a < 3 && inside; ++a) {
      const int ca = c[a] + o[a];
      inside = ca >= 0 && ca < n_[a];
      const double g = o[a] < 0 ? f[a] * h_ : o[a] > 0 ? (1.0 - f[a]) * h_ : 0.0;
      box2 += g * g;
    }
    if (!inside || box2 >= best) continue;
    scan_nearest(cell_index(c[0] + o[0], c[1] + o[1], c[2] + o[2]), qx, qy, qz, best, arg);
  }
  return arg;
}

std::size_t RadiusGrid::cell_of(const Eigen::Vector3d& p) const {
  int c[3];
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / h_)), 0, n_[a] - 1);
  return cell_index(c[0], c[1], c[2]);
}

}  // namespace bayesgrasp::vision
