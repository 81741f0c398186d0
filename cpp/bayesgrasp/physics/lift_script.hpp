// The scripted palm trajectory of a lift test (squeeze, lift, shake, hold) and its outcome
// (see lift_test.hpp).
#pragma once

#include "bayesgrasp/physics/bullet_world.hpp"

namespace bayesgrasp::physics {

/// Steps the world through the script, moving the kinematic `palm` from `hand_pose`, and
/// fills res's outcome (displacement, rotation, squeeze_displacement, height_gain, finite,
/// lifted, steps, skipped_queries). `com_z`: the object's initial centre-of-mass height.
void run_script(BulletWorld& w, btRigidBody* object, btRigidBody* palm, const Iso3& hand_pose, double com_z,
                const LiftOptions& o, LiftResult& res);

}  // namespace bayesgrasp::physics
