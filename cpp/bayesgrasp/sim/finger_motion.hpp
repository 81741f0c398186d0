// How fast a closing finger's links can move: the speed bounds behind conservative advancement.
//
// Finger f closes by one actuator parameter t; a moving phalanx i turns at ratio_i per unit of
// t about its joint axis. A point of link j (i <= j) at distance r from joint i's axis then
// moves at most ratio_i * r per unit of t, so link j moves at most
//   v_j = sum over the moving joints i <= j of ratio_i * arm[i][j],
// with arm[i][j] the largest distance of link j's points from joint i's axis: the length of
// the chain from joint i to joint j plus link j's reach about its own joint. A prismatic joint
// (a jaw, its finger's only phalanx) moves every point of its link at ratio per unit of t:
// arm = 1.
#pragma once

#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/sim/link_geometry.hpp"

namespace bayesgrasp::sim {

constexpr int kMaxPhalanges = 8;  // per finger (stack arrays in the closing steps)

struct FingerMotion {
  std::vector<std::vector<double>> arm;  // arm[i][j], i <= j: see above
  double reach = 0.0;  // radius about the first phalanx joint that holds every point the finger can reach
};

/// One FingerMotion per finger; throws std::invalid_argument for a finger with more than
/// kMaxPhalanges phalanges.
std::vector<FingerMotion> make_finger_motion(const HandModel& hand, const LinkShapes& links);

/// Marks the phalanges that still close (not frozen by a contact, coupled, below their upper
/// limit) and returns the first of them, or the number of phalanges when none does.
int moving_phalanges(const Finger& finger, const bool* frozen, const double* angles, bool* moving);

/// Speed bound v_j of phalanx j (see above) given the moving phalanges from `first` on.
double link_speed(const Finger& finger, const FingerMotion& motion, const bool* moving, int first, int j);

}  // namespace bayesgrasp::sim
