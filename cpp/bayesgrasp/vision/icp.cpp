#include "bayesgrasp/vision/icp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace bayesgrasp::vision {

namespace {
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The normal equations A x = b of one linearised step, x = (rotation vector, translation);
// returns the number of pairs within max_distance.
int normal_equations(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, const Iso3& T,
                     const std::vector<double>& d, const std::vector<int>& idx, double max_distance, Mat6& A,
                     Vec6& b) {
  A.setZero();
  b.setZero();
  int n = 0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (!(d[i] < max_distance)) continue;
    const Vec3 s = model.samples.points[idx[i]].cast<double>();
    const Vec3 nn = model.samples.normals[idx[i]].cast<double>();
    const Vec3 q = T * scene[i];
    const double r = (q - s).dot(nn);
    Vec6 J;
    J.head<3>() = q.cross(nn);
    J.tail<3>() = nn;
    A.noalias() += J * J.transpose();
    b.noalias() -= J * r;
    ++n;
  }
  return n;
}
}  // namespace

Iso3 point_to_plane_icp(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, Iso3 T,
                        double max_distance, int iterations, double tolerance) {
  std::vector<double> d;
  std::vector<int> idx;
  Mat6 A;
  Vec6 b;
  for (int it = 0; it < iterations; ++it) {
    nearest_samples(model, scene, T, d, idx);
    if (normal_equations(model, scene, T, d, idx, max_distance, A, b) < 6) break;
    A.diagonal().array() += 1e-9;
    const Vec6 x = A.ldlt().solve(b);
    if (!x.allFinite()) break;
    Iso3 dT = Iso3::Identity();
    const double ang = x.head<3>().norm();
    if (ang > 0) dT.linear() = Eigen::AngleAxisd(ang, x.head<3>() / ang).toRotationMatrix();
    dT.translation() = x.tail<3>();
    T = dT * T;
    if (ang < tolerance && x.tail<3>().norm() < tolerance) break;
  }
  return T;
}

}  // namespace bayesgrasp::vision
