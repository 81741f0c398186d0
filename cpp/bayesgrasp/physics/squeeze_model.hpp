// The squeeze of the lift test as the Barrett BH8 drives it: the per-step motor law of every
// finger, free of Bullet (hand_bodies applies it to the hinges, lift_script calls it).
// Other closing schemes (HandModel::closing): a linkage keeps its first phalanx driven and the
// others coupled by (S1) (a negative ratio turns a pad back), with no breakaway; a hand with one
// motor per joint (independent) drives every joint with its own torque, nothing coupled, no
// worm lock. What follows is the BH8's breakaway scheme.
//
// One motor per finger. It drives one phalanx at a time, the finger's *driven* phalanx a
// (initially 0, the proximal): a velocity servo towards `closing_speed` with at most the
// hand file's torque for that joint (Phalanx::torque, the hand's actuation) or, when
// `finger_torque` > 0, that override at every joint. The phalanges after a are coupled to it by the
// transmission (the hand file's closing law q_j = offset_j + ratio_j t): while coupled,
//     dq_j/dt = (ratio_j / ratio_a) dq_a/dt,   j > a,                                   (S1)
// a rigid gear, so their loads are carried by the same motor (virtual work: the torque at
// joint a is tau_a + sum_j (ratio_j / ratio_a) tau_j). Breakaway (the TorqueSwitch): when the
// driven phalanx is stopped by the object - it touches the object and its joint has turned
// slower than `kStallFraction` x closing_speed for `kStallTime` s - or it reaches its upper
// limit, it is locked where it is and the motor drives the next phalanx (a + 1, the distal),
// at most its own joint's torque, with the phalanges after it coupled by (S1). The last
// phalanx stays driven: the finger then keeps pressing, stalled or not. A stalled finger whose
// driven phalanx does not touch the object (the distal touches first) does not break away:
// it presses through the coupling, as the real hand does.
// Worm drive (not backdrivable): the driven joint does not open by more than the worm's
// `backlash` - its lower limit is the largest angle it has reached minus the backlash (a
// ratchet) - and the coupled ones cannot either, held to it by the transmission; upper limits
// are the hand file's. A locked phalanx stays between the largest angle it reached and that
// minus the backlash. Why a backlash: a rigid contact is resolved a little at a time, so a
// pressing finger is always slightly inside the object; a lock at the deepest angle reached
// holds that overlap, and pushing it out against the lock makes a force the motor never
// applied (a BH8 fingertip pressed on a fixed plate at its 1.1 N m: 26 N after 0.25 s and 34 N
// after 0.4 s, still rising, instead of 20 N; tests/python/test_lift_strength.py). A backlash of 0.01 rad (0.5 mm at a 5 cm
// fingertip) lets the overlap out while the motor keeps pressing, at the motor's force. There is no travel limit: a finger follows the object wherever
// it goes, up to its joint limits.
// Start: the closed grasp may already be past breakaway (the contact simulator froze the
// proximal and closed the distal further): phalanx a is taken as broken away when a later
// phalanx is more than 1e-3 rad beyond the closing law at a's angle, or a is at its limit.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp::physics {

/// A parallel jaw (a prismatic phalanx) is driven like a fingertip this far from a joint: its
/// speed is closing_speed x kJawLever (m/s), its backlash backlash x kJawLever (m), and a
/// finger_torque override of tau N m presses it with tau / kJawLever N.
constexpr double kJawLever = 0.05;

/// One joint's command for the next step (joint angles in HandModel layout, closing > 0;
/// metres, m/s and N for a prismatic joint).
struct JointCommand {
  bool driven = false;     // the finger's motor drives this joint
  double velocity = 0.0;   // rad/s, the motor's target (driven joints)
  double max_torque = 0.0; // N m, the motor's torque limit (driven joints)
  bool coupled = false;    // follows the driven joint by (S1) with `gear_ratio`
  double gear_ratio = 0.0; // dq_j/dt over dq_a/dt (coupled joints)
  double lower = 0.0;      // rad, this step's limits (the worm lock below, the hand file above)
  double upper = 0.0;
};

class SqueezeModel {
 public:
  /// Stall detection: the driven joint turns slower than this fraction of closing_speed ...
  static constexpr double kStallFraction = 0.1;
  /// ... for this long (s) while its phalanx touches the object.
  static constexpr double kStallTime = 0.01;

  /// `joints`: the closed grasp (HandModel layout, within the limits); `closing_speed` rad/s,
  /// `finger_torque` N m (> 0: every driven joint's limit; 0: each phalanx's Phalanx::torque),
  /// `time_step` s, `backlash` rad (the worm's, >= 0).
  SqueezeModel(const HandModel& hand, const Eigen::VectorXd& joints, double closing_speed, double finger_torque,
               double time_step, double backlash = 0.0);

  /// One step of the law from the joints' angles and velocities (HandModel layout) and which
  /// hand links touch the object (indexed like HandModel::links()). Returns true when a
  /// finger broke away (the couplings changed).
  bool update(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, const std::vector<char>& link_touches);

  const std::vector<JointCommand>& commands() const { return cmd_; }
  /// The phalanx finger f's motor drives (0 = proximal; > 0 after breakaway).
  int driven(int finger) const { return driven_[finger]; }
  /// Joint index (HandModel layout) of finger f's driven phalanx.
  int driven_joint(int finger) const;

 private:
  void set_commands();
  bool at_upper(int finger, int phalanx, const Eigen::VectorXd& q) const;

  HandModel hand_;
  double speed_, torque_, backlash_;
  int stall_steps_;
  std::vector<int> driven_, stall_;
  std::vector<double> reached_;  // largest angle reached per joint (the worm lock)
  std::vector<JointCommand> cmd_;
};

}  // namespace bayesgrasp::physics
