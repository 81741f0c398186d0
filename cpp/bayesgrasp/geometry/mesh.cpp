#include "bayesgrasp/geometry/mesh.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp {

void validate_mesh(const TriMesh& mesh) {
  if (mesh.V.rows() == 0) throw std::invalid_argument("mesh has no vertices");
  if (mesh.F.rows() == 0) throw std::invalid_argument("mesh has no faces");
  if (!mesh.V.allFinite()) throw std::invalid_argument("mesh vertices contain NaN or infinity");
  const int n = static_cast<int>(mesh.V.rows());
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= n)
    throw std::invalid_argument("mesh face indices out of range [0, " + std::to_string(n) + ")");
}

MassProperties mass_properties(const TriMesh& mesh, double density) {
  validate_mesh(mesh);
  if (!(density > 0.0) || !std::isfinite(density))
    throw std::invalid_argument("density must be positive and finite");
  // Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid, accumulated over
  // signed tetrahedra (origin, a, b, c). Reference point: the vertex centroid, for accuracy.
  const Vec3 ref = mesh.V.colwise().mean().transpose();
  double vol = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();  // integral of r r^T
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vec3 a = mesh.V.row(mesh.F(f, 0)).transpose() - ref;
    const Vec3 b = mesh.V.row(mesh.F(f, 1)).transpose() - ref;
    const Vec3 c = mesh.V.row(mesh.F(f, 2)).transpose() - ref;
    const double d = a.dot(b.cross(c));  // 6 x signed volume
    vol += d / 6.0;
    first += d / 24.0 * (a + b + c);
    // For a tetrahedron with a vertex at the origin: integral r r^T =
    // det/120 * (a a^T + b b^T + c c^T + s s^T), s = a + b + c.
    const Vec3 s = a + b + c;
    second += d / 120.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  MassProperties mp;
  mp.volume = vol;
  if (std::abs(vol) < 1e-15) throw std::invalid_argument("mesh encloses no volume");
  const Vec3 com_local = first / vol;
  mp.com = com_local + ref;
  mp.mass = density * std::abs(vol);
  const double sign = vol > 0 ? 1.0 : -1.0;
  // Second moment about the centre of mass.
  const Mat3 C = sign * density * (second - vol * com_local * com_local.transpose());
  mp.inertia = C.trace() * Mat3::Identity() - C;
  return mp;
}

double max_vertex_distance(const TriMesh& mesh, const Vec3& point) {
  if (mesh.V.rows() == 0) return 0.0;
  return std::sqrt((mesh.V.rowwise() - point.transpose()).rowwise().squaredNorm().maxCoeff());
}

Eigen::AlignedBox3d bounds(const TriMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) box.extend(mesh.V.row(i).transpose());
  return box;
}

TriMesh transformed(const TriMesh& mesh, const Iso3& T) {
  TriMesh out;
  out.F = mesh.F;
  out.V = (mesh.V * T.linear().transpose()).rowwise() + T.translation().transpose();
  return out;
}

Iso3 planar_pose(double x, double y, double yaw, double z) {
  Iso3 T = Iso3::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  T.translation() = Vec3(x, y, z);
  return T;
}

Iso3 pose_from_matrix(const Eigen::Matrix4d& M) {
  if (!M.allFinite()) throw std::invalid_argument("pose contains NaN or infinity");
  const Mat3 R = M.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isApprox(Mat3::Identity(), 1e-6) || R.determinant() < 0)
    throw std::invalid_argument("pose rotation block is not a proper rotation");
  if (M.row(3).head<3>().norm() > 1e-9 || std::abs(M(3, 3) - 1.0) > 1e-9)
    throw std::invalid_argument("pose bottom row must be [0, 0, 0, 1]");
  Iso3 T = Iso3::Identity();
  T.linear() = R;
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

}  // namespace bayesgrasp
