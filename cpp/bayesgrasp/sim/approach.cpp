#include "bayesgrasp/sim/approach.hpp"

#include <algorithm>
#include <cmath>

#include "bayesgrasp/sim/closing.hpp"
#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

constexpr double kStartGap = 0.01;  // the open hand starts this far before the object's box (m)
constexpr double kTableReach = 1.0;  // a descending hand past the object looks this far for the table (m)

/// The link distances of one approach step.
struct StepDistances {
  bool object_touch = false;            // a link is within the tolerance of the object
  bool table_touch = false;             // ... of the table, moving down onto it
  double smallest = kInf;               // smallest known travel to a contact (deferred queries aside)
  std::vector<LinkDistance*> deferred;  // links whose object query is deferred
  std::vector<int> deferred_link;
};

/// What an approach knows about the obstacles ahead: `descent` = -d_z (the table is reached
/// after a travel of height / descent when it is positive) and the object's smallest
/// coordinate along the direction (the object lies beyond that plane).
struct Ahead {
  double descent = 0.0;
  double object_near = -kInf;
  Vec3 back = Vec3::UnitZ();  // -direction
};

/// Evaluates every link at the hand pose H (poses: the link poses, filled here).
StepDistances evaluate_links(const SimScene& s, const Iso3& H, const std::vector<Iso3>& local, const Ahead& ahead,
                             Approach& a, std::vector<Iso3>& poses) {
  const double tol = s.options.contact_tolerance, descent = ahead.descent;
  StepDistances d;
  for (int l = 0; l < s.hand.num_links(); ++l) poses[l] = H * local[l];
  for (int l = 0; l < s.hand.num_links(); ++l) {
    if (s.links[l].empty()) continue;
    LinkDistance& c = a.distances[l];
    // separating plane: the link's deepest point along the direction to the object's plane
    const double plane =
        ahead.object_near > -kInf ? link_min_along(s.links[l], poses[l], ahead.back) + ahead.object_near : -kInf;
    evaluate_link(s, l, poses[l], c, a.queries, plane);
    if (descent > 0.0) {
      d.smallest = std::min(d.smallest, c.table / descent);
      if (c.table < tol) d.table_touch = true;
    }
    if (c.deferred) d.deferred.push_back(&c), d.deferred_link.push_back(l);
    else d.smallest = std::min(d.smallest, c.lower);
    if (c.upper < tol) d.object_touch = true;
  }
  return d;
}

/// The safe travel: every point moves at speed 1 along the direction, so a link's object term
/// is its distance itself; deferred queries are resolved against the smallest known travel.
double safe_travel(const SimScene& s, StepDistances& d, const std::vector<Iso3>& poses, Approach& a) {
  return resolve_deferred(
      d.deferred.data(), static_cast<int>(d.deferred.size()), d.smallest, [](int, double x) { return x; },
      [](int, double x) { return x; },
      [&](int k, double cap) {
        const int l = d.deferred_link[k];
        return distance_below(s, l, poses[l], cap, a.queries, &d.deferred[k]->warm);
      });
}

/// Height of the open hand's lowest point above the table at hand pose H.
double lowest_height(const SimScene& s, const Iso3& H, const Eigen::VectorXd& open_joints) {
  const std::vector<Iso3> poses = s.hand.link_poses(H, open_joints);
  double h = kInf;
  for (int l = 0; l < s.hand.num_links(); ++l)
    if (!s.links[l].empty()) h = std::min(h, table_distance(s.links[l], poses[l]));
  return h;
}

}  // namespace

Approach approach_until_contact(const SimScene& s, const Iso3& start, const Vec3& direction, const Vec3& last,
                                const Eigen::VectorXd& open_joints) {
  const double tol = s.options.contact_tolerance;
  Ahead ahead;
  ahead.descent = s.options.table ? -direction.z() : 0.0;
  ahead.back = -direction;
  // Along -z the 26-DOP holds this plane already.
  if (direction != -Vec3::UnitZ()) ahead.object_near = (s.mesh.V * direction).minCoeff();
  const double descent = ahead.descent;
  Approach a;
  a.pose = start;
  a.direction = direction;
  a.distances.assign(s.hand.num_links(), LinkDistance{});
  // Link poses of the open hand relative to the palm: the approach only translates them.
  const std::vector<Iso3> local = s.hand.link_poses(Iso3::Identity(), open_joints);
  std::vector<Iso3> poses(local.size());
  // Past `last` the hand gives up; descending onto a table, only kTableReach further on.
  const double limit = direction.dot(last) + (descent > 0.0 ? kTableReach : 0.0);
  Vec3 position = start.translation();
  for (int it = 0; it < s.options.max_iterations; ++it) {
    a.pose.translation() = position;
    StepDistances d = evaluate_links(s, a.pose, local, ahead, a, poses);
    if (d.object_touch || d.table_touch) {
      a.stopped_by_table = !d.object_touch;
      break;
    }
    const double u = direction.dot(position);
    if (u > limit) break;
    const double travel = safe_travel(s, d, poses, a);
    ++a.iterations;
    // (descending, a step ends at most just past the limit: the table may lie far beyond it)
    double dz = std::max(travel - 0.5 * tol, 0.0);
    if (descent > 0.0) dz = std::min(dz, limit - u + 1e-9);
    position += dz * direction;
    for (LinkDistance& c : a.distances) c.carried_lower = std::max(0.0, c.lower - dz);
    if (!position.allFinite()) position = last;  // nothing ahead (no table, no link with a distance)
  }
  return a;
}

void back_off(const SimScene& s, Approach& a, double distance) {
  if (!(distance > 0.0)) return;
  a.pose.translation() -= distance * a.direction;
  // Every point moved by `distance`: the distances found are still lower bounds after it.
  // (Without pruning, carried bounds only scale rel_err's allowance: they restart at 0.)
  const bool carry = s.pruning();
  for (LinkDistance& c : a.distances) {
    c.carried_lower = carry && c.current ? std::max(0.0, c.lower - distance) : 0.0;
    c.current = false;
  }
}

double closing_sweep_depth(const HandModel& hand, const LinkShapes& links, double spread) {
  double t_end = 0.0;
  for (const Finger& f : hand.fingers()) t_end = std::max(t_end, f.t_max());
  const double step = 0.5 * M_PI / 180.0;
  double depth = 0.0;
  for (double t = 0.0; t <= t_end + 0.5 * step; t += step)
    depth = std::max(depth, depth_below_palm(hand, links, hand.coupled_joints(spread, t)));
  return depth;
}

ApproachLine approach_line(const SimScene& s, const ApproachSpec& a, const Eigen::VectorXd& open_joints,
                           double depth) {
  const Vec3& d = a.direction;
  // The object's box along d: the coordinates of its nearest and farthest corners.
  double nearest = kInf, farthest = -kInf;
  for (int k = 0; k < 8; ++k) {
    const double u = d.dot(s.object.box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)));
    nearest = std::min(nearest, u), farthest = std::max(farthest, u);
  }
  const Vec3 foot = a.target - d.dot(a.target) * d;  // the palm's line at coordinate 0 along d
  ApproachLine line;
  line.start = HandModel::approach_pose(d, a.roll, foot + (nearest - depth - kStartGap) * d);
  if (s.options.table) {
    line.start_height = lowest_height(s, line.start, open_joints);
    if (d.z() < 0.0 && line.start_height < 0.5 * kStartGap) {
      line.start.translation() += ((kStartGap - line.start_height) / d.z()) * d;
      line.start_height = lowest_height(s, line.start, open_joints);
    }
  }
  line.last = foot + (farthest + 0.5 * depth) * d;
  return line;
}

GraspResult approach_grasp(const SimScene& s, const ApproachSpec& a, double spread, double standoff) {
  const SimOptions& o = s.options;
  const Eigen::VectorXd open = s.hand.coupled_joints(spread, 0.0);
  const ApproachLine line = approach_line(s, a, open, depth_below_palm(s.hand, s.links, open));
  GraspResult r = open_hand(s, line.start, spread);
  // The start is clear of the object (behind its box along the direction); only the table can
  // hold the open hand (when the direction does not descend).
  if (line.start_height < -1e-9) {
    mark_collision_at_start(s, r);
    return r;
  }
  Approach m = approach_until_contact(s, line.start, a.direction, line.last, open);
  double back = standoff;
  if (o.table && o.table_clearance >= 0.0 && a.direction == -Vec3::UnitZ())  // keep the sweep above the table
    back = std::max(back, s.sweep_depth + o.table_clearance - m.pose.translation().z());
  back_off(s, m, back);
  r = close_hand(s, m.pose, spread, &m.distances);
  r.stopped_by_table = m.stopped_by_table;
  r.distance_queries += m.queries;
  r.iterations += m.iterations;
  return r;
}

}  // namespace bayesgrasp::sim
