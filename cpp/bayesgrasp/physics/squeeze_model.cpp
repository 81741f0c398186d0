#include "bayesgrasp/physics/squeeze_model.hpp"

#include <algorithm>
#include <cmath>

namespace bayesgrasp::physics {

namespace {
constexpr double kLimitSlack = 1e-4;     // rad: a joint this close to its upper limit is at it
constexpr double kBeyondCoupling = 1e-3; // rad: a start this far past the closing law has broken away
}  // namespace

SqueezeModel::SqueezeModel(const HandModel& hand, const Eigen::VectorXd& joints, double closing_speed,
                           double finger_torque, double time_step, double backlash)
    : hand_(hand),
      speed_(closing_speed),
      torque_(finger_torque),
      backlash_(backlash),
      stall_steps_(std::max(1, static_cast<int>(std::ceil(kStallTime / time_step - 1e-9)))),
      driven_(hand.fingers().size(), 0),
      stall_(hand.fingers().size(), 0),
      reached_(joints.data(), joints.data() + joints.size()),
      cmd_(static_cast<size_t>(hand.num_joints())) {
  // The breakaway state of the closed grasp: phalanx a has broken away when it is at its limit
  // or a later phalanx is past the closing law at a's actuator value t_a = (q_a - offset_a) / ratio_a.
  // Only the breakaway scheme breaks away: a linkage's driver (phalanx 0) stays driven, and an
  // independent hand drives every joint (set_commands).
  for (size_t f = 0; f < hand.fingers().size() && hand.closing() == Closing::Breakaway; ++f) {
    const Finger& fi = hand.fingers()[f];
    const int n = static_cast<int>(fi.phalanges.size());
    int a = 0;
    while (a + 1 < n) {
      const Phalanx& pa = fi.phalanges[a];
      const double t = (joints[fi.first_joint + a] - pa.offset) / pa.ratio;
      bool beyond = at_upper(static_cast<int>(f), a, joints);
      for (int j = a + 1; j < n && !beyond; ++j) {
        const Phalanx& pj = fi.phalanges[j];
        const double law = std::clamp(pj.offset + pj.ratio * t, pj.lower, pj.upper);
        beyond = joints[fi.first_joint + j] > law + kBeyondCoupling;
      }
      if (!beyond) break;
      ++a;
    }
    driven_[f] = a;
  }
  set_commands();
}

int SqueezeModel::driven_joint(int finger) const { return hand_.fingers()[finger].first_joint + driven_[finger]; }

bool SqueezeModel::at_upper(int finger, int phalanx, const Eigen::VectorXd& q) const {
  const Finger& fi = hand_.fingers()[finger];
  return q[fi.first_joint + phalanx] >= fi.phalanges[phalanx].upper - kLimitSlack;
}

bool SqueezeModel::update(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, const std::vector<char>& link_touches) {
  for (Eigen::Index j = 0; j < q.size(); ++j) reached_[j] = std::max(reached_[j], q[j]);
  bool changed = false;
  for (size_t f = 0; f < hand_.fingers().size() && hand_.closing() == Closing::Breakaway; ++f) {
    const Finger& fi = hand_.fingers()[f];
    const int a = driven_[f];
    if (a + 1 >= static_cast<int>(fi.phalanges.size())) continue;  // the last phalanx stays driven
    const int ja = fi.first_joint + a;
    // Stopped by the object: touching it and (nearly) still for kStallTime.
    const bool slow = qdot[ja] < kStallFraction * speed_ * (fi.phalanges[a].prismatic ? kJawLever : 1.0);
    stall_[f] = slow && link_touches[fi.phalanges[a].link] ? stall_[f] + 1 : 0;
    if (stall_[f] >= stall_steps_ || at_upper(static_cast<int>(f), a, q)) {
      driven_[f] = a + 1;  // breakaway: lock phalanx a, drive the next one
      stall_[f] = 0;
      changed = true;
    }
  }
  set_commands();
  return changed;
}

void SqueezeModel::set_commands() {
  for (size_t f = 0; f < hand_.fingers().size(); ++f) {
    const Finger& fi = hand_.fingers()[f];
    const int a = driven_[f];
    for (int j = 0; j < static_cast<int>(fi.phalanges.size()); ++j) {
      const Phalanx& ph = fi.phalanges[j];
      const int k = fi.first_joint + j;
      JointCommand& c = cmd_[k];
      c = JointCommand{};
      c.upper = ph.upper;
      const double lever = ph.prismatic ? kJawLever : 1.0;  // a jaw's metres per radian
      if (hand_.closing() == Closing::Independent) {
        // One motor per joint: each presses with its own torque; backdrivable (no worm lock).
        c.driven = true;
        c.velocity = lever * speed_;
        c.max_torque = torque_ > 0 ? torque_ / lever : ph.torque;
        c.lower = ph.lower;
        continue;
      }
      // The worm: never opens by more than its backlash below the largest angle reached.
      c.lower = std::max(ph.lower, std::min(reached_[k], ph.upper) - lever * backlash_);
      if (j < a) {
        // Locked by the breakaway where it was (the largest angle reached).
        c.upper = std::min(reached_[k], ph.upper);
      } else if (j == a) {
        c.driven = true;
        c.velocity = lever * speed_;
        c.max_torque = torque_ > 0 ? torque_ / lever : ph.torque;  // the override, else the hand file's
      } else {
        // Coupled: the transmission holds it to the driven joint, whose worm holds both; its
        // own limits are the hand file's.
        c.coupled = true;
        c.gear_ratio = ph.ratio / fi.phalanges[a].ratio;  // (S1)
        c.lower = ph.lower;
      }
    }
  }
}

}  // namespace bayesgrasp::physics
