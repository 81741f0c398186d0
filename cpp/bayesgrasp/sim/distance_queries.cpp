#include "bayesgrasp/sim/distance_queries.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>

#include "bayesgrasp/sim/bvh_distance.hpp"
#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

constexpr fcl::GJKSolverType kSolver = fcl::GST_INDEP;

/// FCL distance from one shape to the object; the shape's offset (the capsule radius of a
/// segment) is subtracted and the link-side nearest point moved onto the capsule's surface.
/// With a finite `cap`, only distances below it are searched for; kInf if there are none.
double shape_distance(const SimScene& s, const LinkShape& shape, const Iso3& T, const fcl::DistanceRequestd& req,
                      NearestPoints* e, double cap = kInf) {
  fcl::DistanceResultd res;
  const bool capped = cap < kInf && cap + shape.offset > 0.0;  // FCL stops at once on a best <= 0
  if (capped) res.min_distance = cap + shape.offset;
  bvh_distance(s.object.bvh.get(), shape.geometry.get(), T * shape.geometry_frame, req, res,
               s.options.tie_tolerance);
  if (capped && res.b1 == fcl::DistanceResultd::NONE) return kInf;  // nothing below cap
  const double d = res.min_distance - shape.offset;
  if (e && d < e->distance) {
    e->distance = d;
    e->triangle = static_cast<int>(res.b1);
    e->object_point = res.nearest_points[0];
    e->link_point = res.nearest_points[1];
    if (shape.offset > 0) {
      const Vec3 g = e->object_point - e->link_point;
      if (g.norm() > 1e-12) e->link_point += shape.offset * g.normalized();
    }
  }
  return d;
}

/// shape_distance from a known pair distance `start` (FCL's raw distance, kInf if none);
/// records the nearest pair in `pair`.
double shape_distance_from(const SimScene& s, const LinkShape& shape, const Iso3& T, const fcl::DistanceRequestd& req,
                           double cap, double start, int* pair) {
  fcl::DistanceResultd res;
  const double capped = cap < kInf && cap + shape.offset > 0.0 ? cap + shape.offset : kInf;
  const double preset = std::min(capped, start);
  if (preset < kInf && preset > 0.0) res.min_distance = preset;  // FCL stops at once on a best <= 0
  else if (preset <= 0.0) return start - shape.offset;  // touching pair known (only when start <= 0)
  bvh_distance(s.object.bvh.get(), shape.geometry.get(), T * shape.geometry_frame, req, res,
               s.options.tie_tolerance);
  double raw;
  if (res.b1 != fcl::DistanceResultd::NONE) {
    raw = res.min_distance;
    if (pair) pair[0] = static_cast<int>(res.b1), pair[1] = static_cast<int>(res.b2);
  } else {
    raw = start;  // nothing strictly nearer than the preset
  }
  if (raw >= capped) return kInf;
  return raw - shape.offset;
}

/// FCL's raw distance of a known (object triangle, link-mesh triangle) pair, computed as FCL
/// computes it at a leaf.
double pair_distance(const SimScene& s, const LinkShape& shape, const Iso3& T, const int* pair) {
  // the link mesh's frame relative to the object's (identity), as FCL forms it
  const fcl::Transform3d tf = fcl::Transform3d::Identity().inverse(Eigen::Isometry) * (T * shape.geometry_frame);
  const MeshView& om = s.object.mesh;
  const fcl::Triangle& a = om.triangles[pair[0]];
  const fcl::Triangle& b = shape.mesh.triangles[pair[1]];
  fcl::Vector3d P, Q;
  return fcl::detail::TriangleDistance<double>::triDistance(om.vertices[a[0]], om.vertices[a[1]], om.vertices[a[2]],
                                                            shape.mesh.vertices[b[0]], shape.mesh.vertices[b[1]],
                                                            shape.mesh.vertices[b[2]], tf, P, Q);
}

}  // namespace

NearestPoints nearest_points(const SimScene& s, int link, const Iso3& T, int& queries, double cap) {
  NearestPoints e;
  fcl::DistanceRequestd req(true);
  req.gjk_solver_type = kSolver;
  for (const LinkShape& shape : s.links[link]) {
    shape_distance(s, shape, T, req, &e, cap);
    ++queries;
  }
  return e;
}

double distance_below(const SimScene& s, int link, const Iso3& T, double cap, int& queries, WarmStart* warm) {
  fcl::DistanceRequestd req;
  req.gjk_solver_type = kSolver;
  double d = kInf;
  const std::vector<LinkShape>& shapes = s.links[link];
  for (size_t k = 0; k < shapes.size(); ++k) {
    const LinkShape& shape = shapes[k];
    ++queries;
    int* pair = warm && k < kWarmShapes && shape.mesh.triangles ? warm->pair[k] : nullptr;
    const double start = pair && pair[0] >= 0 ? pair_distance(s, shape, T, pair) : kInf;
    d = std::min(d, shape_distance_from(s, shape, T, req, cap, start, pair));
  }
  return d;
}

void advancing_bounds(const SimScene& s, int link, const Iso3& T, double bd, double carried_lower, double& lower,
                      double& upper, int& queries) {
  if (bd > s.options.box_skip) {
    lower = bd;
    upper = kInf;
    return;
  }
  const double a = s.options.rel_err * std::max(bd, carried_lower);
  fcl::DistanceRequestd req(false, false, a > 0 ? 1e9 : 0.0, a);
  req.gjk_solver_type = kSolver;
  double d = kInf;
  for (const LinkShape& shape : s.links[link]) {
    d = std::min(d, shape_distance(s, shape, T, req, nullptr));
    ++queries;
  }
  upper = d;
  lower = d - a;
}

Vec3 contact_normal(const SimScene& s, const NearestPoints& e) {
  const Vec3 gap = e.link_point - e.object_point;
  if (e.distance > 0.0 && gap.norm() > 1e-7) return gap.normalized();
  return s.object.normals[e.triangle];
}

bool penetrates(const SimScene& s, int link, const Iso3& T, int& queries) {
  const std::vector<LinkShape>& shapes = s.links[link];
  if (s.options.table && table_distance(shapes, T) < -1e-9) return true;
  if (box_distance(shapes, T, s.object) > 0.0) return false;
  const NearestPoints e = nearest_points(s, link, T, queries);
  if (e.distance <= 0.0) return true;
  if (e.distance < s.options.contact_tolerance || e.triangle < 0) return false;  // touching from outside
  // Inside the object: the link lies clearly behind the nearest face (the direction to it
  // is within 60 deg of the inward normal; near an edge the face normal alone is ambiguous).
  const Vec3 g = e.link_point - e.object_point;
  return g.dot(s.object.normals[e.triangle]) < -0.5 * g.norm();
}

bool collides(const SimScene& s, int link, const Iso3& T, int& queries) {
  if (box_distance(s.links[link], T, s.object) > 0.0) return false;
  fcl::CollisionRequestd req;
  req.gjk_solver_type = kSolver;
  for (const LinkShape& shape : s.links[link]) {
    fcl::CollisionResultd res;
    fcl::collide(s.object.bvh.get(), fcl::Transform3d::Identity(), shape.primitive.get(), T * shape.primitive_frame,
                 req, res);
    ++queries;
    if (res.isCollision()) return true;
  }
  return false;
}

bool sliding_blocked(const SimScene& s, int link, const Iso3& T, double margin, int& queries) {
  if (s.options.table && table_distance(s.links[link], T) < 0.0) return true;
  if (box_distance(s.links[link], T, s.object) > margin) return false;
  fcl::DistanceRequestd req;
  req.gjk_solver_type = kSolver;
  for (const LinkShape& shape : s.links[link]) {
    ++queries;
    if (shape_distance(s, shape, T, req, nullptr) < margin) return true;
  }
  return false;
}

}  // namespace bayesgrasp::sim
