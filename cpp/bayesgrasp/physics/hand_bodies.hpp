// The hand in the lift test's Bullet world: a kinematic palm (palm and knuckle shapes: the
// spread is frozen) and, per phalanx, a dynamic body hinged to its parent at its joint, with a
// joint motor that keeps closing with bounded torque and limits that make the joint
// non-backdrivable (see lift_test.hpp).
#pragma once

#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/physics/bullet_world.hpp"

namespace bayesgrasp::physics {

/// Adds the hand at `hand_pose` with closed joints `joints` (link poses `poses`, world);
/// returns the palm body.
btRigidBody* add_hand(BulletWorld& w, const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                      const std::vector<Iso3>& poses, const LiftOptions& o);

}  // namespace bayesgrasp::physics
