#include "bayesgrasp/sim/approach.hpp"

#include <algorithm>
#include <cmath>

#include "bayesgrasp/sim/closing.hpp"

namespace bayesgrasp::sim {

namespace {

/// The link distances of one approach step.
struct StepDistances {
  bool touch = false;                  // a link is within the tolerance of the object or the table
  double smallest = kInf;              // smallest known distance (deferred queries aside)
  std::vector<LinkDistance*> deferred;  // links whose object query is deferred
  std::vector<int> deferred_link;
};

/// Evaluates every link at the hand pose H (poses: the link poses, filled here).
StepDistances evaluate_links(const SimScene& s, const Iso3& H, const std::vector<Iso3>& local, Approach& a,
                             std::vector<Iso3>& poses) {
  const double tol = s.options.contact_tolerance;
  StepDistances d;
  for (int l = 0; l < s.hand.num_links(); ++l) poses[l] = H * local[l];
  for (int l = 0; l < s.hand.num_links(); ++l) {
    if (s.links[l].empty()) continue;
    LinkDistance& c = a.distances[l];
    evaluate_link(s, l, poses[l], c, a.queries);
    d.smallest = std::min(d.smallest, c.table);
    if (c.deferred) d.deferred.push_back(&c), d.deferred_link.push_back(l);
    else d.smallest = std::min(d.smallest, c.lower);
    if (c.upper < tol || c.table < tol) d.touch = true;
  }
  return d;
}

/// The safe travel: every point moves at speed 1 along the direction, so a link's term is its
/// distance itself; deferred queries are resolved against the smallest known distance.
double safe_travel(const SimScene& s, StepDistances& d, const std::vector<Iso3>& poses, Approach& a) {
  return resolve_deferred(
      d.deferred.data(), static_cast<int>(d.deferred.size()), d.smallest, [](int, double x) { return x; },
      [](int, double x) { return x; },
      [&](int k, double cap) {
        const int l = d.deferred_link[k];
        return distance_below(s, l, poses[l], cap, a.queries, &d.deferred[k]->warm);
      });
}

}  // namespace

Approach approach_until_contact(const SimScene& s, const Iso3& start, const Vec3& direction, const Vec3& last,
                                const Eigen::VectorXd& open_joints) {
  const double tol = s.options.contact_tolerance;
  Approach a;
  a.pose = start;
  a.direction = direction;
  a.distances.assign(s.hand.num_links(), LinkDistance{});
  // Link poses of the open hand relative to the palm: the approach only translates them.
  const std::vector<Iso3> local = s.hand.link_poses(Iso3::Identity(), open_joints);
  std::vector<Iso3> poses(local.size());
  const double limit = direction.dot(last);
  Vec3 position = start.translation();
  for (int it = 0; it < s.options.max_iterations; ++it) {
    a.pose.translation() = position;
    StepDistances d = evaluate_links(s, a.pose, local, a, poses);
    if (d.touch) break;
    if (!s.options.table && direction.dot(position) > limit) break;
    const double travel = safe_travel(s, d, poses, a);
    ++a.iterations;
    const double dz = std::max(travel - 0.5 * tol, 0.0);
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

GraspResult top_grasp(const SimScene& s, double x, double y, double yaw, double spread, double standoff) {
  const SimOptions& o = s.options;
  const Eigen::VectorXd open = s.hand.coupled_joints(spread, 0.0);
  // Start with the open hand's lowest point 1 cm above the object (and the table).
  const double depth = depth_below_palm(s.hand, s.links, open);
  const double z0 = std::max(s.object.box.max().z(), o.table ? 0.0 : -kInf) + depth + 0.01;
  const double z_floor = s.object.box.min().z() - 0.5 * depth;  // without a table: give up below the object
  Approach a = approach_until_contact(s, HandModel::top_grasp_pose(x, y, yaw, z0), -Vec3::UnitZ(),
                                      Vec3(x, y, z_floor), open);
  // Keep the closing fingers' sweep above the table (see approach.hpp).
  double raise = standoff;
  if (o.table && o.table_clearance >= 0.0)
    raise = std::max(raise, s.sweep_depth + o.table_clearance - a.pose.translation().z());
  back_off(s, a, raise);
  GraspResult r = close_hand(s, a.pose, spread, &a.distances);
  r.distance_queries += a.queries;
  r.iterations += a.iterations;
  return r;
}

}  // namespace bayesgrasp::sim
