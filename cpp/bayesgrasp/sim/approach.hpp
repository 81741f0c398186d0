// Approach: the open hand moves along a unit direction (world) from a start pose, without
// turning, until a link comes within the contact tolerance of the object or the table; it can
// then back off along the direction by a stand-off before it closes.
//
// Motion by conservative advancement: a translation of length dz moves every point of the
// hand by exactly dz, so with d the smallest link distance to the object (lower bounds carried
// between steps and query pruning as in closing, query_pruning.hpp) the step dz = d - tol / 2
// cannot make a link penetrate. Besides the box and 26-DOP bounds, a link's distance is at
// least the gap along the direction between its deepest point and the plane through the
// object's nearest vertex along the direction (a separating plane while the link is behind
// it; along -z the 26-DOP holds that plane already). The table is a plane: a link at height h reaches it after a
// travel of exactly h / (-d_z) when the direction descends (d_z < 0), and never otherwise (a
// link then touching the table slides along it or leaves it, and does not stop the hand). The
// swept volume of the approach is free, so the closing that follows needs no collision check of
// the open hand.
//
// Where an approach starts and ends (approach_line): the palm centre moves on the line through
// the target along d. It starts where the open hand's deepest point along d (depth_below_palm)
// is 1 cm before the nearest corner of the object's bounding box along d (the hand is then
// clear of the object), moved back further when the direction descends until the open hand is
// at least 5 mm above the table. It gives up once the palm is half the open hand's depth past
// the box's farthest corner along d (`last`), or, descending onto a table, 1 m further on (the
// table of a nearly horizontal approach can lie arbitrarily far ahead).
//
// Top grasps are the approach along d = -z with the palm-down hand (HandModel::top_grasp_pose).
// Along d = -z with a table (only there), the palm then stays at least `table_clearance` above
// the deepest point the closing fingers sweep (SimScene::sweep_depth: the coupled closing path,
// sampled every 0.5 deg): on an object lower than the fingers are long, the fingers wrap it near
// its base instead of striking the table (a hand descending to the object's top would otherwise
// only ever grasp the table).
#pragma once

#include <vector>

#include "bayesgrasp/sim/query_pruning.hpp"

namespace bayesgrasp::sim {

/// Where an approach stopped, and what it learnt about the link distances there.
struct Approach {
  Iso3 pose = Iso3::Identity();         // the hand's pose at the first contact (or at the limit)
  Vec3 direction = -Vec3::UnitZ();      // unit direction of motion (world)
  std::vector<LinkDistance> distances;  // per link, at `pose` (current) or carried lower bounds
  bool stopped_by_table = false;        // a link touched the table, none the object
  int queries = 0, iterations = 0;
};

/// Moves the open hand (joints `open_joints`) from `start` along unit `direction` to the first
/// contact. `last` is the farthest palm position on the line of motion: the hand gives up once
/// it is beyond `last` (it has passed the object), or, descending onto a table, 1 m beyond it.
/// The start pose must be collision-free.
Approach approach_until_contact(const SimScene& s, const Iso3& start, const Vec3& direction, const Vec3& last,
                                const Eigen::VectorXd& open_joints);

/// Moves the hand back against the approach direction by `distance` (>= 0, m); the link
/// distances found stay valid as lower bounds.
void back_off(const SimScene& s, Approach& a, double distance);

/// Deepest point below the palm face (hand +z) reached by any link shape along the coupled
/// closing path (t from 0 to the largest t_max, every 0.5 deg) at the given spread.
double closing_sweep_depth(const HandModel& hand, const LinkShapes& links, double spread);

/// The start pose of an approach and its last palm position (see above); `a.direction` unit,
/// `depth` the open hand's depth_below_palm.
struct ApproachLine {
  Iso3 start = Iso3::Identity();
  Vec3 last = Vec3::Zero();
  double start_height = kInf;  // of the open hand's lowest point above the table at the start (kInf: no table)
};
ApproachLine approach_line(const SimScene& s, const ApproachSpec& a, const Eigen::VectorXd& open_joints,
                           double depth);

/// The approach `a` (unit direction), the stand-off (and the table clearance along -z), then
/// closing. A start in the table is returned as collision_at_start with the hand open.
GraspResult approach_grasp(const SimScene& s, const ApproachSpec& a, double spread, double standoff);

}  // namespace bayesgrasp::sim
