#include "bayesgrasp/belief/relative_pose.hpp"

#include <cmath>

namespace bayesgrasp::belief {

RowMatrixXd relative_planar_pose(const RowMatrixXd& A, const RowMatrixXd& P) {
  if (A.cols() < 3) throw std::invalid_argument("actions: expected at least 3 columns (x, y, yaw)");
  if (P.cols() != 3) throw std::invalid_argument("poses: expected 3 columns (x, y, yaw)");
  if (!A.allFinite()) throw std::invalid_argument("actions: contains NaN or infinity");
  if (!P.allFinite()) throw std::invalid_argument("poses: contains NaN or infinity");
  const Eigen::Index na = A.rows(), n = P.rows(), c = A.cols();
  RowMatrixXd out(na * n, c);
  std::vector<double> cs(n), sn(n);
  for (Eigen::Index j = 0; j < n; ++j) { cs[j] = std::cos(P(j, 2)); sn[j] = std::sin(P(j, 2)); }
  for (Eigen::Index a = 0; a < na; ++a)
    for (Eigen::Index j = 0; j < n; ++j) {
      const double dx = A(a, 0) - P(j, 0), dy = A(a, 1) - P(j, 1);
      double* o = &out(a * n + j, 0);
      o[0] = cs[j] * dx + sn[j] * dy;
      o[1] = -sn[j] * dx + cs[j] * dy;
      double yaw = std::fmod(A(a, 2) - P(j, 2) + M_PI, 2.0 * M_PI);
      if (yaw < 0.0) yaw += 2.0 * M_PI;
      o[2] = yaw - M_PI;
      for (Eigen::Index e = 3; e < c; ++e) o[e] = A(a, e);
    }
  return out;
}

}  // namespace bayesgrasp::belief
