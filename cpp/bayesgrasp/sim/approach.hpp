// Approach: the open hand moves along a unit direction (world) from a start pose, without
// turning, until a link comes within the contact tolerance of the object or the table; it can
// then back off along the direction by a stand-off before it closes.
//
// Motion by conservative advancement: a translation of length dz moves every point of the
// hand by exactly dz, so with d the smallest link distance (object or table; lower bounds
// carried between steps and query pruning as in closing, query_pruning.hpp) the step
// dz = d - tol / 2 cannot make a link penetrate. The swept volume of the approach is free, so
// the closing that follows needs no collision check of the open hand.
//
// Top grasps are the approach along -z of the palm-down hand (HandModel::top_grasp_pose) from
// above the object. With a table, the palm then stays at least `table_clearance` above the
// deepest point the closing fingers sweep (SimScene::sweep_depth: the coupled closing path,
// sampled every 0.5 deg): on an object lower than the fingers are long, the fingers wrap it
// near its base instead of striking the table (a hand descending to the object's top would
// otherwise only ever grasp the table).
#pragma once

#include <vector>

#include "bayesgrasp/sim/query_pruning.hpp"

namespace bayesgrasp::sim {

/// Where an approach stopped, and what it learnt about the link distances there.
struct Approach {
  Iso3 pose = Iso3::Identity();         // the hand's pose at the first contact (or at the limit)
  Vec3 direction = -Vec3::UnitZ();      // unit direction of motion (world)
  std::vector<LinkDistance> distances;  // per link, at `pose` (current) or carried lower bounds
  int queries = 0, iterations = 0;
};

/// Moves the open hand (joints `open_joints`) from `start` along unit `direction` to the first
/// contact. `last` is the farthest palm position on the line of motion: without a table the
/// hand gives up once it is beyond `last` (it has passed the object). The start pose must be
/// collision-free.
Approach approach_until_contact(const SimScene& s, const Iso3& start, const Vec3& direction, const Vec3& last,
                                const Eigen::VectorXd& open_joints);

/// Moves the hand back against the approach direction by `distance` (>= 0, m); the link
/// distances found stay valid as lower bounds.
void back_off(const SimScene& s, Approach& a, double distance);

/// Deepest point below the palm face (hand +z) reached by any link shape along the coupled
/// closing path (t from 0 to the largest t_max, every 0.5 deg) at the given spread.
double closing_sweep_depth(const HandModel& hand, const LinkShapes& links, double spread);

/// Palm-down approach at (x, y, yaw) along -z, stand-off and table clearance, then closing.
GraspResult top_grasp(const SimScene& s, double x, double y, double yaw, double spread, double standoff);

}  // namespace bayesgrasp::sim
