// The hand in the lift test's Bullet world: a kinematic palm (palm and knuckle shapes: the
// spread is frozen) and, per phalanx, a dynamic body hinged to its parent at its joint (a jaw,
// a prismatic phalanx: on a slider, its motor a force). The
// hinge carries the finger motor when the squeeze model drives that joint; two one-row
// constraints per joint carry the rest of the model (squeeze_model.hpp): the joint's limits
// (the worm lock below, the hand file's limit above, or locked) and, while coupled, the
// transmission to the driven joint (S1), each with an error term so that angles do not drift.
#pragma once

#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/physics/bullet_world.hpp"
#include "bayesgrasp/physics/squeeze_model.hpp"

namespace bayesgrasp::physics {

class AngularRow;  // one velocity row along a joint axis between two bodies (hand_bodies.cpp)

/// The hand's bodies and joints; joints indexed in HandModel layout (entry 0, the frozen
/// spread, unused).
struct HandBodies {
  btRigidBody* palm = nullptr;
  std::vector<btRigidBody*> link_body;     // per HandModel link: its body (the palm for palm and knuckles)
  std::vector<int> joint_link;             // per joint: the phalanx's link (-1 for the spread)
  std::vector<int> joint_parent;           // per joint: the parent link (0 = palm)
  std::vector<btHingeConstraint*> hinge;   // per revolute joint (else null)
  std::vector<btSliderConstraint*> slider; // per prismatic joint, a jaw (else null)
  std::vector<Vec3> slide_origin;          // per prismatic joint: the jaw's start in its parent's frame
  std::vector<Vec3> slide_axis;            // ... and its closing direction (-d_f) there
  std::vector<AngularRow*> limit_row;      // per joint: limits (worm lock, upper, locked)
  std::vector<std::vector<AngularRow*>> coupling_row;  // per joint j: (S1) to phalanx a < j of its finger
  Eigen::VectorXd q0;                      // the closed grasp (hinge angle 0)

  /// Joint angles (rad) and closing velocities (rad/s), HandModel layout (spread = q0's).
  Eigen::VectorXd angles() const;
  Eigen::VectorXd velocities() const;
  /// Applies one step of the squeeze model: motors, limits and couplings. `couplings_changed`:
  /// take new coupling references (at the start and after a breakaway).
  void apply(const HandModel& hand, const SqueezeModel& model, const Eigen::VectorXd& q, bool couplings_changed,
             double time_step);

 private:
  Eigen::VectorXd q_ref_;  // angles when the couplings were last set
};

/// Adds the hand at `hand_pose` with closed joints `joints` (link poses `poses`, world).
HandBodies add_hand(BulletWorld& w, const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                    const std::vector<Iso3>& poses, const LiftOptions& o);

}  // namespace bayesgrasp::physics
