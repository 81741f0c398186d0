// What one touch is (thesis ch. 2, Pub. I): the grasp the robot executed and what its sensors
// read afterwards. The robot knows the executed grasp exactly: either a palm-down top grasp at a
// world (x, y, yaw), which descends along -z to the first contact, backs off by the stand-off
// (and the simulator's table clearance) and closes; or a closing at a known world hand pose. It
// reads, after closing, the joint angles, a 0/1 contact flag per link (touching the object) and
// the hand pose at which the hand closed (for a top grasp the height is where the descent
// stopped, so it is a reading too).
#pragma once

#include <cstdint>
#include <vector>

#include "bayesgrasp/sim/grasp_simulator.hpp"

namespace bayesgrasp::touch {

/// The executed grasp, in the world frame.
struct TouchGrasp {
  enum class Kind { TopGrasp, Closing };
  Kind kind = Kind::TopGrasp;
  double x = 0.0, y = 0.0, yaw = 0.0;   ///< TopGrasp: where the palm-down hand descends
  double standoff = 0.0;                ///< TopGrasp: back-off after the first contact (m, >= 0)
  Iso3 hand_pose = Iso3::Identity();    ///< Closing: the hand pose at which the hand closes
  double spread = 0.0;                  ///< finger spread (rad)

  static TouchGrasp top(double x, double y, double yaw, double spread, double standoff = 0.0);
  static TouchGrasp closing(const Iso3& hand_pose, double spread);
};

/// The sensor readings after the closing.
struct TouchReadings {
  Eigen::VectorXd joints;             ///< (J,) HandModel layout; entry 0 (the spread) is commanded
  std::vector<uint8_t> contact;       ///< (L,) 1 = the link touches the object
  Iso3 hand_pose = Iso3::Identity();  ///< world pose at which the hand closed

  int contact_count() const;
};

/// Throws std::invalid_argument naming the argument unless the grasp is finite and its spread
/// and stand-off are within range for `hand`.
void check_grasp(const HandModel& hand, const TouchGrasp& g);

/// Throws std::invalid_argument naming the field unless the readings fit `hand` (J joints, L
/// flags of 0 or 1) and are finite.
void check_readings(const HandModel& hand, const TouchReadings& r, const char* name = "measured");

/// The readings a simulated grasp gives.
TouchReadings readings_of(const GraspResult& r);

/// The grasp executed on `world` (a simulator whose object is in the world frame): the robot's
/// reality when the simulator plays it.
GraspResult execute(const GraspSimulator& world, const TouchGrasp& g);

}  // namespace bayesgrasp::touch
