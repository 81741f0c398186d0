// Farthest-point sampling: the Nystrom landmarks of the CPD kernel (cpd.hpp).
#include <algorithm>
#include <limits>

#include "bayesgrasp/deform/cpd.hpp"

namespace bayesgrasp::deform {

std::vector<int> farthest_points(const Points& points, int k) {
  const int n = static_cast<int>(points.rows());
  k = std::max(0, std::min(k, n));
  std::vector<int> out;
  if (k == 0) return out;
  out.reserve(k);
  Eigen::VectorXd dist = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  int next = 0;
  for (int j = 0; j < k; ++j) {
    out.push_back(next);
    const Eigen::RowVector3d p = points.row(next);
    for (int i = 0; i < n; ++i) dist(i) = std::min(dist(i), (points.row(i) - p).squaredNorm());
    if (dist.maxCoeff(&next) <= 0.0) break;  // every point is a landmark's copy: no new one
    // maxCoeff keeps the first of the farthest, so ties resolve the same way every time
  }
  return out;
}

}  // namespace bayesgrasp::deform
