#include "bayesgrasp/geometry/surface_sampling.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp {

namespace {
Vec3 vertex(const TriMesh& mesh, Eigen::Index f, int k) { return mesh.V.row(mesh.F(f, k)).transpose(); }

// Twice the area of face f times its unit normal: (v1 - v0) x (v2 - v0).
Vec3 area_normal(const TriMesh& mesh, Eigen::Index f) {
  const Vec3 v0 = vertex(mesh, f, 0);
  return (vertex(mesh, f, 1) - v0).cross(vertex(mesh, f, 2) - v0);
}
}  // namespace

double surface_area(const TriMesh& mesh) {
  double a = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) a += 0.5 * area_normal(mesh, f).norm();
  return a;
}

SurfaceSamples sample_surface(const TriMesh& mesh, int n, std::uint64_t seed) {
  validate_mesh(mesh);
  if (n <= 0) throw std::invalid_argument("n: number of samples must be positive, got " + std::to_string(n));
  // Cumulative face areas (the triangle choice) and unit face normals (zero for degenerate faces).
  const Eigen::Index F = mesh.F.rows();
  std::vector<double> cum(F);
  std::vector<Vec3> normals(F);
  double total = 0;
  for (Eigen::Index f = 0; f < F; ++f) {
    const Vec3 c = area_normal(mesh, f);
    const double a = 0.5 * c.norm();
    total += a;
    cum[f] = total;
    normals[f] = a > 0 ? c.normalized() : Vec3::Zero();
  }
  if (!(total > 0)) throw std::invalid_argument("mesh has no surface area");
  Rng rng(mix_seed(seed));
  std::uniform_real_distribution<double> U(0.0, 1.0);
  SurfaceSamples s;
  s.points.resize(n, 3);
  s.normals.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    const double r = U(rng) * total;
    Eigen::Index f = std::lower_bound(cum.begin(), cum.end(), r) - cum.begin();
    f = std::min<Eigen::Index>(f, F - 1);
    while (f > 0 && normals[f].isZero()) --f;  // never a zero-area face
    double a = U(rng), b = U(rng);
    if (a + b > 1) {  // reflect into the triangle
      a = 1 - a;
      b = 1 - b;
    }
    const Vec3 v0 = vertex(mesh, f, 0), v1 = vertex(mesh, f, 1), v2 = vertex(mesh, f, 2);
    s.points.row(i) = (v0 + a * (v1 - v0) + b * (v2 - v0)).transpose();
    s.normals.row(i) = normals[f].transpose();
  }
  return s;
}

}  // namespace bayesgrasp
