#include "bayesgrasp/belief/relative_pose.hpp"

#include <stdexcept>
#include <string>

namespace bayesgrasp::belief {

namespace {

void check_grasps(const RowMatrixXd& m, const char* name) {
  if (m.cols() < 3) throw std::invalid_argument(std::string(name) + ": expected at least 3 columns (x, y, yaw)");
  if (!m.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
}

// Row `o` = grasp row `g` of G placed by frame f (the extra columns copied). Not inlined: one
// compiled copy, so the all-pairs and the one-to-one composition round alike, bit for bit.
__attribute__((noinline)) void place(const PlanarFrame& f, const RowMatrixXd& G, Eigen::Index g, double* o) {
  f.to_world(G(g, 0), G(g, 1), o[0], o[1]);
  o[2] = wrap_angle(G(g, 2) + f.yaw);
  for (Eigen::Index e = 3; e < G.cols(); ++e) o[e] = G(g, e);
}

}  // namespace

void check_planar_poses(const RowMatrixXd& m, const char* name) {
  if (m.cols() != 3) throw std::invalid_argument(std::string(name) + ": expected 3 columns (x, y, yaw)");
  if (!m.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
}

std::vector<PlanarFrame> planar_frames(const RowMatrixXd& P) {
  std::vector<PlanarFrame> frames(static_cast<std::size_t>(P.rows()));
  for (Eigen::Index j = 0; j < P.rows(); ++j) frames[j] = PlanarFrame(P(j, 0), P(j, 1), P(j, 2));
  return frames;
}

RowMatrixXd relative_planar_pose(const RowMatrixXd& A, const RowMatrixXd& P) {
  check_grasps(A, "actions");
  check_planar_poses(P, "poses");
  const Eigen::Index na = A.rows(), n = P.rows(), c = A.cols();
  RowMatrixXd out(na * n, c);
  const std::vector<PlanarFrame> frames = planar_frames(P);
  for (Eigen::Index a = 0; a < na; ++a)
    for (Eigen::Index j = 0; j < n; ++j) {
      double* o = &out(a * n + j, 0);
      frames[j].to_local(A(a, 0), A(a, 1), o[0], o[1]);
      o[2] = wrap_angle(A(a, 2) - P(j, 2));
      for (Eigen::Index e = 3; e < c; ++e) o[e] = A(a, e);
    }
  return out;
}

RowMatrixXd compose_planar_pose(const RowMatrixXd& R, const RowMatrixXd& P) {
  check_grasps(R, "relative");
  check_planar_poses(P, "poses");
  const Eigen::Index nr = R.rows(), n = P.rows();
  RowMatrixXd out(nr * n, R.cols());
  const std::vector<PlanarFrame> frames = planar_frames(P);
  for (Eigen::Index r = 0; r < nr; ++r)
    for (Eigen::Index j = 0; j < n; ++j) place(frames[j], R, r, &out(r * n + j, 0));
  return out;
}

RowMatrixXd compose_planar_pose_paired(const RowMatrixXd& R, const RowMatrixXd& P) {
  check_grasps(R, "relative");
  check_planar_poses(P, "poses");
  if (P.rows() != R.rows())
    throw std::invalid_argument("poses: expected one pose per relative grasp (" + std::to_string(R.rows()) +
                                "), got " + std::to_string(P.rows()));
  RowMatrixXd out(R.rows(), R.cols());
  for (Eigen::Index i = 0; i < R.rows(); ++i) place(PlanarFrame(P(i, 0), P(i, 1), P(i, 2)), R, i, &out(i, 0));
  return out;
}

}  // namespace bayesgrasp::belief
