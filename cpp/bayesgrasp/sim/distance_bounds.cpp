#include "bayesgrasp/sim/distance_bounds.hpp"

#include <algorithm>
#include <cmath>

namespace bayesgrasp::sim {

double table_distance(const std::vector<LinkShape>& shapes, const Iso3& T) {
  double d = kInf;
  for (const LinkShape& s : shapes) {
    if (s.capsule) {
      d = std::min(d, std::min((T * s.p0).z(), (T * s.p1).z()) - s.radius);
    } else if (s.convex) {
      for (const Vec3& v : s.vertices) d = std::min(d, (T * v).z());
    } else {
      const Vec3 c = T * s.center;
      const double ext = std::abs(T.linear()(2, 0)) * s.half_extents.x() +
                         std::abs(T.linear()(2, 1)) * s.half_extents.y() +
                         std::abs(T.linear()(2, 2)) * s.half_extents.z();
      d = std::min(d, c.z() - ext);
    }
  }
  return d;
}

Vec3 lowest_point(const std::vector<LinkShape>& shapes, const Iso3& T) {
  double best = kInf;
  Vec3 p = Vec3::Zero();
  for (const LinkShape& s : shapes) {
    if (s.capsule) {
      const Vec3 a = T * s.p0, b = T * s.p1;
      Vec3 q = std::abs(a.z() - b.z()) < 1e-9 ? Vec3(0.5 * (a + b)) : (a.z() < b.z() ? a : b);
      if (q.z() - s.radius < best) best = q.z() - s.radius, p = q;
    } else if (s.convex) {
      for (const Vec3& v : s.vertices) {
        const Vec3 q = T * v;
        if (q.z() < best) best = q.z(), p = q;
      }
    } else {
      const Mat3 R = T.linear();
      Vec3 q = T * s.center;
      for (int k = 0; k < 3; ++k) {
        const double rz = R(2, k);
        if (std::abs(rz) > 1e-9) q -= (rz > 0 ? 1.0 : -1.0) * s.half_extents[k] * R.col(k);
      }
      if (q.z() < best) best = q.z(), p = q;
    }
  }
  return p;
}

double box_distance(const std::vector<LinkShape>& shapes, const Iso3& T, const ObjectGeometry& object) {
  Eigen::AlignedBox3d b;
  for (const LinkShape& s : shapes) {
    if (s.capsule) {
      const Vec3 a = T * s.p0, c = T * s.p1;
      b.extend(a.cwiseMin(c) - Vec3::Constant(s.radius));
      b.extend(a.cwiseMax(c) + Vec3::Constant(s.radius));
    } else if (s.convex) {
      for (const Vec3& v : s.vertices) b.extend(T * v);
    } else {
      const Vec3 c = T * s.center;
      const Vec3 e = T.linear().cwiseAbs() * s.half_extents;
      b.extend(c - e);
      b.extend(c + e);
    }
  }
  const Eigen::AlignedBox3d& box = object.box;
  const Vec3 gap = (box.min() - b.max()).cwiseMax(b.min() - box.max()).cwiseMax(0.0);
  double lb = gap.norm();
  // separating-axis bound over the object's 26-DOP (tighter than the box off its corners)
  for (int k = 0; k < ObjectGeometry::kDop; ++k)
    lb = std::max(lb, link_min_along(shapes, T, object.dop_directions[k]) - object.dop_extent[k]);
  return lb;
}

double link_min_along(const std::vector<LinkShape>& shapes, const Iso3& T, const Vec3& n) {
  double lo = kInf;
  for (const LinkShape& s : shapes) {
    if (s.capsule) {
      lo = std::min(lo, std::min(n.dot(T * s.p0), n.dot(T * s.p1)) - s.radius);
    } else if (s.convex) {
      for (const Vec3& v : s.vertices) lo = std::min(lo, n.dot(T * v));
    } else {
      const Vec3 nl = T.linear().transpose() * n;
      lo = std::min(lo, n.dot(T * s.center) - nl.cwiseAbs().dot(s.half_extents));
    }
  }
  return lo;
}

}  // namespace bayesgrasp::sim
