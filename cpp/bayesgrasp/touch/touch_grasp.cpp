#include "bayesgrasp/touch/touch_grasp.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::touch {

TouchGrasp TouchGrasp::top(double x, double y, double yaw, double spread, double standoff) {
  TouchGrasp g;
  g.kind = Kind::TopGrasp;
  g.x = x, g.y = y, g.yaw = yaw, g.spread = spread, g.standoff = standoff;
  return g;
}

TouchGrasp TouchGrasp::closing(const Iso3& hand_pose, double spread) {
  TouchGrasp g;
  g.kind = Kind::Closing;
  g.hand_pose = hand_pose, g.spread = spread;
  return g;
}

int TouchReadings::contact_count() const {
  int n = 0;
  for (uint8_t c : contact) n += c != 0;
  return n;
}

void check_grasp(const HandModel& hand, const TouchGrasp& g) {
  hand.check_spread(g.spread, "grasp.spread");
  if (g.kind == TouchGrasp::Kind::TopGrasp) {
    if (!std::isfinite(g.x) || !std::isfinite(g.y) || !std::isfinite(g.yaw))
      throw std::invalid_argument("grasp: x, y and yaw must be finite");
    if (!(g.standoff >= 0.0) || !std::isfinite(g.standoff))
      throw std::invalid_argument("grasp.standoff: must be >= 0 and finite, got " + std::to_string(g.standoff));
  } else if (!g.hand_pose.matrix().allFinite()) {
    throw std::invalid_argument("grasp.hand_pose: contains NaN or infinity");
  }
}

void check_readings(const HandModel& hand, const TouchReadings& r, const char* name) {
  const std::string n(name);
  if (r.joints.size() != hand.num_joints())
    throw std::invalid_argument(n + ".joints: expected " + std::to_string(hand.num_joints()) + " joint angles, got " +
                                std::to_string(r.joints.size()));
  if (!r.joints.allFinite()) throw std::invalid_argument(n + ".joints: contains NaN or infinity");
  if (static_cast<int>(r.contact.size()) != hand.num_links())
    throw std::invalid_argument(n + ".contact: expected " + std::to_string(hand.num_links()) + " flags, got " +
                                std::to_string(r.contact.size()));
  for (uint8_t c : r.contact)
    if (c > 1) throw std::invalid_argument(n + ".contact: flags must be 0 or 1");
  if (!r.hand_pose.matrix().allFinite()) throw std::invalid_argument(n + ".hand_pose: contains NaN or infinity");
}

TouchReadings readings_of(const GraspResult& r) {
  TouchReadings out;
  out.joints = r.joints;
  out.contact = r.link_contact;
  out.hand_pose = r.hand_pose;
  return out;
}

GraspResult execute(const GraspSimulator& world, const TouchGrasp& g) {
  check_grasp(world.hand(), g);
  if (g.kind == TouchGrasp::Kind::TopGrasp) return world.top_grasp(g.x, g.y, g.yaw, g.spread, g.standoff);
  return world.close(g.hand_pose, g.spread);
}

}  // namespace bayesgrasp::touch
