// GraspSimulator: the public entry points. Arguments are validated here, once; the steps live
// in sim_scene / link_geometry (preparation), approach (approaches and top grasps), closing and
// fixed_step_closing, and grasp_batch (many grasps in threads).
#include "bayesgrasp/sim/grasp_simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/sim/approach.hpp"
#include "bayesgrasp/sim/closing.hpp"
#include "bayesgrasp/sim/grasp_batch.hpp"
#include "bayesgrasp/sim/sim_scene.hpp"

namespace bayesgrasp {

struct GraspSimulator::Impl {
  sim::SimScene scene;
};

void validate(const SimOptions& o) {
  if (!(o.contact_tolerance > 0) || !std::isfinite(o.contact_tolerance))
    throw std::invalid_argument("contact_tolerance: must be positive and finite, got " +
                                std::to_string(o.contact_tolerance));
  if (!(o.rel_err >= 0) || !(o.rel_err < 1))
    throw std::invalid_argument("rel_err: must lie in [0, 1), got " + std::to_string(o.rel_err));
  if (!(o.tie_tolerance >= 0) || !(o.tie_tolerance < 0.1 * o.contact_tolerance))
    throw std::invalid_argument("tie_tolerance: must lie in [0, contact_tolerance / 10), got " +
                                std::to_string(o.tie_tolerance));
  if (!(o.box_skip > o.contact_tolerance) || !std::isfinite(o.box_skip))
    throw std::invalid_argument("box_skip: must be finite and exceed contact_tolerance, got " +
                                std::to_string(o.box_skip));
  if (!std::isfinite(o.table_clearance))
    throw std::invalid_argument("table_clearance: must be finite (negative disables the rule)");
  if (o.max_iterations < 1)
    throw std::invalid_argument("max_iterations: must be >= 1, got " + std::to_string(o.max_iterations));
}

namespace sim {

SimScene make_scene(const HandModel& hand, const TriMesh& object, const SimOptions& options) {
  validate_mesh(object);
  validate(options);
  SimScene s;
  s.hand = hand;
  s.mesh = object;
  s.options = options;
  s.object = make_object_geometry(object, options.bv);
  s.links = make_link_shapes(hand, options);
  s.fingers = make_finger_motion(hand, s.links);
  // The sweep's depth does not depend on the spread (a rotation about the palm normal).
  s.sweep_depth = closing_sweep_depth(hand, s.links, hand.spread_default());
  return s;
}

}  // namespace sim

namespace {

void check_pose(const Iso3& H, const char* name = "hand_pose") {
  if (!H.matrix().allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
}

void check_standoff(double standoff) {
  if (!(standoff >= 0) || !std::isfinite(standoff))
    throw std::invalid_argument("standoff: must be >= 0 and finite, got " + std::to_string(standoff));
}

std::string indexed(const char* name, int i) { return i < 0 ? name : std::string(name) + "[" + std::to_string(i) + "]"; }

/// `a` with its direction normalised; errors name `direction`, `roll`, `target` (with [i] for
/// entry i of a batch, i >= 0). With a table, a target below it (z < 0) is an error.
ApproachSpec checked_approach(const ApproachSpec& a, bool table, int i = -1) {
  ApproachSpec out = a;
  out.direction = unit_direction(a.direction, indexed(i < 0 ? "direction" : "directions", i).c_str());
  if (!std::isfinite(a.roll)) throw std::invalid_argument(indexed(i < 0 ? "roll" : "rolls", i) + ": must be finite");
  const std::string target = indexed(i < 0 ? "target" : "targets", i);
  if (!a.target.allFinite()) throw std::invalid_argument(target + ": contains NaN or infinity");
  if (table && a.target.z() < 0.0)
    throw std::invalid_argument(target + ": below the table (z = " + std::to_string(a.target.z()) + " < 0)");
  return out;
}

}  // namespace

GraspSimulator::GraspSimulator(const HandModel& hand, const TriMesh& object, const SimOptions& options)
    : impl_(std::make_unique<Impl>(Impl{sim::make_scene(hand, object, options)})) {}

GraspSimulator::~GraspSimulator() = default;
GraspSimulator::GraspSimulator(GraspSimulator&&) noexcept = default;
GraspSimulator& GraspSimulator::operator=(GraspSimulator&&) noexcept = default;

const HandModel& GraspSimulator::hand() const { return impl_->scene.hand; }
const TriMesh& GraspSimulator::object() const { return impl_->scene.mesh; }
const SimOptions& GraspSimulator::options() const { return impl_->scene.options; }
const sim::SimScene& GraspSimulator::scene() const { return impl_->scene; }

GraspResult GraspSimulator::close(const Iso3& hand_pose, double spread) const {
  check_pose(hand_pose);
  hand().check_spread(spread);
  return sim::close_hand(impl_->scene, hand_pose, spread);
}

GraspResult GraspSimulator::close_fixed_step(const Iso3& hand_pose, double spread, double step) const {
  check_pose(hand_pose);
  hand().check_spread(spread);
  if (!(step > 0) || !std::isfinite(step))
    throw std::invalid_argument("step: must be positive and finite, got " + std::to_string(step));
  return sim::close_hand_fixed_step(impl_->scene, hand_pose, spread, step);
}

GraspResult GraspSimulator::top_grasp(double x, double y, double yaw, double spread, double standoff) const {
  if (!std::isfinite(x)) throw std::invalid_argument("x: must be finite");
  if (!std::isfinite(y)) throw std::invalid_argument("y: must be finite");
  if (!std::isfinite(yaw)) throw std::invalid_argument("yaw: must be finite");
  hand().check_spread(spread);
  check_standoff(standoff);
  return sim::approach_grasp(impl_->scene, {-Vec3::UnitZ(), yaw, Vec3(x, y, 0.0)}, spread, standoff);
}

GraspResult GraspSimulator::approach(const ApproachSpec& approach, double spread, double standoff) const {
  const ApproachSpec a = checked_approach(approach, options().table);
  hand().check_spread(spread);
  check_standoff(standoff);
  return sim::approach_grasp(impl_->scene, a, spread, standoff);
}

double GraspSimulator::link_object_distance(const Iso3& hand_pose, const Eigen::VectorXd& q, int link) const {
  check_pose(hand_pose);
  hand().check_joints(q, 1e-9, "q");
  if (link < 0 || link >= hand().num_links())
    throw std::invalid_argument("link: must lie in [0, " + std::to_string(hand().num_links()) + "), got " +
                                std::to_string(link));
  const sim::SimScene& s = impl_->scene;
  if (s.links[link].empty()) return sim::kInf;
  const std::vector<Iso3> poses = s.hand.link_poses(hand_pose, q);
  int queries = 0;
  return sim::nearest_points(s, link, poses[link], queries).distance;
}

GraspBatch GraspSimulator::close_batch(const std::vector<Iso3>& poses, const std::vector<double>& spreads,
                                       int threads) const {
  if (spreads.size() != poses.size() && spreads.size() != 1)
    throw std::invalid_argument("spreads: need one per pose or a single value, got " + std::to_string(spreads.size()) +
                                " for " + std::to_string(poses.size()) + " poses");
  for (size_t i = 0; i < poses.size(); ++i) check_pose(poses[i], ("hand_poses[" + std::to_string(i) + "]").c_str());
  for (double s : spreads) hand().check_spread(s, "spreads");
  const sim::SimScene& s = impl_->scene;
  return sim::grasp_batch(s, static_cast<int>(poses.size()), threads, [&](int i) {
    return sim::close_hand(s, poses[i], spreads.size() == 1 ? spreads[0] : spreads[i]);
  });
}

GraspBatch GraspSimulator::top_grasp_batch(const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& xyyaw,
                                           double spread, double standoff, int threads) const {
  if (!xyyaw.allFinite()) throw std::invalid_argument("xyyaw: contains NaN or infinity");
  hand().check_spread(spread);
  check_standoff(standoff);
  const sim::SimScene& s = impl_->scene;
  return sim::grasp_batch(s, static_cast<int>(xyyaw.rows()), threads, [&](int i) {
    return sim::approach_grasp(s, {-Vec3::UnitZ(), xyyaw(i, 2), Vec3(xyyaw(i, 0), xyyaw(i, 1), 0.0)}, spread, standoff);
  });
}

GraspBatch GraspSimulator::approach_batch(const std::vector<ApproachSpec>& approaches, double spread,
                                          double standoff, int threads) const {
  std::vector<ApproachSpec> checked(approaches.size());
  for (size_t i = 0; i < approaches.size(); ++i)
    checked[i] = checked_approach(approaches[i], options().table, static_cast<int>(i));
  hand().check_spread(spread);
  check_standoff(standoff);
  const sim::SimScene& s = impl_->scene;
  return sim::grasp_batch(s, static_cast<int>(checked.size()), threads,
                          [&](int i) { return sim::approach_grasp(s, checked[i], spread, standoff); });
}

}  // namespace bayesgrasp
