// The scripted palm trajectory of a lift test (squeeze, lift, shake, hold), the squeeze model
// stepped with it, the outcome and the optional trace (see lift_test.hpp).
#pragma once

#include "bayesgrasp/physics/bullet_world.hpp"
#include "bayesgrasp/physics/hand_bodies.hpp"
#include "bayesgrasp/physics/squeeze_model.hpp"

namespace bayesgrasp::physics {

/// Number of steps of the script: ceil(total time / time_step).
long script_steps(const LiftOptions& o);

/// Steps the world through the script, moving the kinematic palm from `hand_pose` and driving
/// the fingers by `model`, and fills res's outcome (displacement, rotation,
/// squeeze_displacement, height_gain, finite, lifted, steps, skipped_queries, breakaway).
/// `com_z`: the object's initial centre-of-mass height. `trace` (if not null, with `every` set):
/// the per-step record.
void run_script(BulletWorld& w, btRigidBody* object, HandBodies& hand_bodies, const HandModel& hand,
                SqueezeModel& model, const Iso3& hand_pose, double com_z, const LiftOptions& o, LiftResult& res,
                LiftTrace* trace);

}  // namespace bayesgrasp::physics
