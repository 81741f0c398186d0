#include "bayesgrasp/task/hand_clearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::task {

namespace {

/// A shape's bounding sphere in its link frame.
struct Bound {
  Vec3 centre;
  double radius;
};

Bound bound_of(const Shape& s) {
  if (s.type == Shape::Type::Capsule) return {0.5 * (s.p0 + s.p1), 0.5 * (s.p1 - s.p0).norm() + s.radius};
  if (s.type == Shape::Type::Convex) return {s.center, s.radius};
  return {s.center, s.half_extents.norm()};
}

/// Lowest z of a shape placed by T (world).
double lowest_z(const Shape& s, const Iso3& T) {
  if (s.type == Shape::Type::Capsule) return std::min((T * s.p0).z(), (T * s.p1).z()) - s.radius;
  if (s.type == Shape::Type::Convex) {
    double z = std::numeric_limits<double>::infinity();
    for (const Vec3& v : s.vertices) z = std::min(z, (T * v).z());
    return z;
  }
  const Vec3 c = T * s.center;
  return c.z() - (T.linear().row(2).cwiseAbs() * s.half_extents)(0);
}

struct PlacedShape {
  const Shape* shape;
  Iso3 world_to_link;
  Vec3 centre_world;
  double radius;
};

std::vector<PlacedShape> place(const HandModel& hand, const std::vector<Iso3>& link_poses, double margin) {
  std::vector<PlacedShape> out;
  for (int l = 0; l < hand.num_links(); ++l)
    for (const Shape& s : hand.links()[l].shapes) {
      const Bound b = bound_of(s);
      out.push_back({&s, link_poses[l].inverse(), link_poses[l] * b.centre, b.radius + margin});
    }
  return out;
}

}  // namespace

void validate(const ClearanceOptions& o) {
  if (!(o.margin >= 0.0) || !std::isfinite(o.margin)) throw std::invalid_argument("margin: must be >= 0 and finite");
}

double shape_depth(const Shape& s, const Vec3& p, double margin) {
  if (s.type == Shape::Type::Capsule) {
    const Vec3 ab = s.p1 - s.p0;
    const double len2 = ab.squaredNorm();
    const double u = len2 > 0 ? std::clamp((p - s.p0).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return s.radius + margin - (p - (s.p0 + u * ab)).norm();
  }
  if (s.type == Shape::Type::Convex) return margin - s.plane_distance(p);  // exact inside, a bound outside
  // box: depth = min over axes of (half extent + margin - |offset|) when inside on all axes
  const Vec3 d = (p - s.center).cwiseAbs() - s.half_extents - Vec3::Constant(margin);
  if ((d.array() > 0).any()) return -d.cwiseMax(0.0).norm();
  return -d.maxCoeff();
}

Clearance hand_clearance(const HandModel& hand, const Eigen::VectorXd& q, const std::vector<Iso3>& poses,
                         const CloudPoints& cloud, const ClearanceOptions& options, int threads) {
  hand.check_joints(q);
  validate(options);
  if (!cloud.allFinite()) throw std::invalid_argument("cloud: contains NaN or infinity");
  const int N = static_cast<int>(poses.size());
  for (int i = 0; i < N; ++i)
    if (!poses[i].matrix().allFinite()) throw std::invalid_argument("poses: pose " + std::to_string(i) + " is not finite");
  Clearance out;
  out.table.setZero(N);
  out.cloud.setZero(N);
  Eigen::AlignedBox3d cloud_box;
  for (Eigen::Index k = 0; k < cloud.rows(); ++k) cloud_box.extend(cloud.row(k).transpose());
  const int nt = thread_count_for(threads, N);
#pragma omp parallel for schedule(dynamic, 4) num_threads(nt)
  for (int i = 0; i < N; ++i) {
    const std::vector<Iso3> links = hand.link_poses(poses[i], q);
    double below = 0.0, deepest = 0.0;
    for (int l = 0; l < hand.num_links(); ++l)
      for (const Shape& s : hand.links()[l].shapes)
        if (options.table) below = std::max(below, options.margin - lowest_z(s, links[l]));
    for (const PlacedShape& ps : place(hand, links, options.margin)) {
      if (cloud_box.isEmpty() || cloud_box.exteriorDistance(ps.centre_world) > ps.radius) continue;
      for (Eigen::Index k = 0; k < cloud.rows(); ++k) {
        const Vec3 p = cloud.row(k).transpose();
        if ((p - ps.centre_world).squaredNorm() > ps.radius * ps.radius) continue;
        deepest = std::max(deepest, shape_depth(*ps.shape, ps.world_to_link * p, options.margin));
      }
    }
    out.table[i] = below;
    out.cloud[i] = deepest;
  }
  return out;
}

}  // namespace bayesgrasp::task
