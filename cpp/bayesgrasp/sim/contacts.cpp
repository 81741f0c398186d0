// The open hand, the collision check at the start, and the final contacts of a closed grasp.
#include <algorithm>

#include "bayesgrasp/sim/closing.hpp"
#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

/// The object contact of link l at pose T, if it is within the tolerance.
void add_object_contact(const SimScene& s, int l, const Iso3& T, const LinkDistance& c, GraspResult& r) {
  const double tol = s.options.contact_tolerance;
  const bool prune = s.pruning();
  // Known far at this pose; with pruning, a lower bound carried to this pose can show the
  // link far too, and the query only looks for distances below the tolerance (the same
  // contact when there is one: see distance_queries.hpp).
  if (c.current && c.lower >= tol) return;
  if (prune && !c.current && c.carried_lower >= tol) return;
  const NearestPoints e = nearest_points(s, l, T, r.distance_queries, prune ? tol : kInf);
  if (!(e.distance < tol && e.triangle >= 0)) return;
  Contact k;
  k.point = e.object_point;
  k.normal = contact_normal(s, e);
  k.link = l;
  k.penetration = std::max(0.0, -e.distance);
  k.triangle = e.triangle;
  r.contacts.push_back(k);
  r.link_contact[l] = 1;
}

void add_table_contact(const SimScene& s, int l, const Iso3& T, GraspResult& r) {
  const double d = table_distance(s.links[l], T);
  if (!(d < s.options.contact_tolerance)) return;
  Contact k;
  k.point = table_point(s.links[l], T);
  k.normal = Vec3::UnitZ();
  k.link = l;
  k.penetration = std::max(0.0, -d);
  k.on_table = true;
  r.contacts.push_back(k);
  r.table_contact[l] = 1;
}

}  // namespace

GraspResult open_hand(const SimScene& s, const Iso3& H, double spread) {
  GraspResult r;
  r.hand_pose = H;
  r.joints = s.hand.coupled_joints(spread, 0.0);
  return r;
}

bool starts_in_collision(const SimScene& s, GraspResult& r) {
  const std::vector<Iso3> poses = s.hand.link_poses(r.hand_pose, r.joints);
  const int L = s.hand.num_links();
  for (int l = 0; l < L; ++l) {
    if (s.links[l].empty() || !penetrates(s, l, poses[l], r.distance_queries)) continue;
    mark_collision_at_start(s, r);
    return true;
  }
  return false;
}

void mark_collision_at_start(const SimScene& s, GraspResult& r) {
  r.collision_at_start = true;
  r.link_contact.assign(s.hand.num_links(), 0);
  r.table_contact.assign(s.hand.num_links(), 0);
}

void collect_contacts(const SimScene& s, const std::vector<LinkDistance>& known, GraspResult& r) {
  const std::vector<Iso3> poses = s.hand.link_poses(r.hand_pose, r.joints);
  const int L = s.hand.num_links();
  r.link_contact.assign(L, 0);
  r.table_contact.assign(L, 0);
  for (int l = 0; l < L; ++l) {
    if (s.links[l].empty()) continue;
    add_object_contact(s, l, poses[l], known[l], r);
    if (s.options.table) add_table_contact(s, l, poses[l], r);
  }
}

}  // namespace bayesgrasp::sim
