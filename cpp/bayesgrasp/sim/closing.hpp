// Closing the hand (auto-grasp) from its open preshape at a fixed hand pose: by conservative
// advancement with breakaway (closing.cpp, the simulator's method) or GraspIt!-style in fixed
// actuator steps with collision checks (fixed_step_closing.cpp, the reference), and the final
// contacts (contacts.cpp). See grasp_simulator.hpp for the method.
#pragma once

#include <vector>

#include "bayesgrasp/sim/query_pruning.hpp"

namespace bayesgrasp::sim {

/// The open hand at pose H with the given spread: preshape joints, no contacts yet.
GraspResult open_hand(const SimScene& s, const Iso3& H, double spread);

/// Whether a link of the open hand `r` penetrates the object or the table; if so, marks r as
/// collision_at_start (mark_collision_at_start).
bool starts_in_collision(const SimScene& s, GraspResult& r);

/// Marks r as collision_at_start with no contacts (its fingers stay open).
void mark_collision_at_start(const SimScene& s, GraspResult& r);

/// The contacts of r at its joints and hand pose (at most one object and one table contact
/// per link). `known` holds what the closing knows about each link's distances.
void collect_contacts(const SimScene& s, const std::vector<LinkDistance>& known, GraspResult& r);

/// Auto-grasp by conservative advancement from the open preshape at H. `from_approach`: the
/// link distances an approach left (the hand is then known to be free: the approach's swept
/// volume was); nullptr checks the open hand for a collision first.
GraspResult close_hand(const SimScene& s, const Iso3& H, double spread,
                       const std::vector<LinkDistance>* from_approach = nullptr);

/// The same auto-grasp GraspIt!-style: the actuator advances in steps of `step` rad with a
/// boolean collision check after each; a collision is located by bisection.
GraspResult close_hand_fixed_step(const SimScene& s, const Iso3& H, double spread, double step);

}  // namespace bayesgrasp::sim
