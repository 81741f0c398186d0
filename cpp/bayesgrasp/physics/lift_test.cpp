// LiftTester: option checks, the object's preparation (lift_object), and one lift test as the
// sequence of its steps: the shape for the grasp, the Bullet world with the object and the
// table (lift_object), the hand (hand_bodies), the script and its outcome (lift_script).
#include "bayesgrasp/physics/lift_test.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/physics/hand_bodies.hpp"
#include "bayesgrasp/physics/lift_object.hpp"
#include "bayesgrasp/physics/lift_script.hpp"
#include "bayesgrasp/common/checks.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp {

struct LiftTester::Impl {
  HandModel hand;
  LiftOptions opt;
  physics::LiftObject object;
};

void validate(const LiftOptions& o) {
  require_non_negative(o.mu, "mu");
  require_non_negative(o.table_mu, "table_mu");
  require_positive(o.density, "density");
  require_positive(o.time_step, "time_step");
  require_at_least(o.solver_iterations, 1, "solver_iterations");
  require_non_negative(o.solver_residual, "solver_residual");
  require_in(o.warmstart_factor, 0.0, 1.0, "warmstart_factor");
  require_non_negative(o.squeeze_time, "squeeze_time");
  require_non_negative(o.lift_height, "lift_height");
  require_positive(o.lift_time, "lift_time");
  require_non_negative(o.shake_amplitude, "shake_amplitude");
  require_positive(o.shake_frequency, "shake_frequency");
  require_non_negative(o.shake_time, "shake_time");
  require_non_negative(o.hold_time, "hold_time");
  require_non_negative(o.finger_torque, "finger_torque");
  require_non_negative(o.closing_speed, "closing_speed");
  require_non_negative(o.worm_backlash, "worm_backlash");
  require_positive(o.link_mass, "link_mass");
  require_non_negative(o.drive_inertia, "drive_inertia");
  require_positive(o.success_distance, "success_distance");
  require_positive(o.tet_depth, "tet_depth");
  require_non_negative(o.margin, "margin");
  // The script's steps, ceil(total / time_step), must be countable and bounded.
  const double total = o.squeeze_time + o.lift_time + o.shake_time + o.hold_time;
  const double steps = total / o.time_step;
  if (!(steps <= static_cast<double>(kMaxLiftSteps)))
    throw std::invalid_argument("squeeze_time + lift_time + shake_time + hold_time (" + std::to_string(total) +
                                " s) over time_step (" + std::to_string(o.time_step) + " s) gives " +
                                std::to_string(steps) + " steps, more than " + std::to_string(kMaxLiftSteps));
  if (!(physics::script_steps(o) >= 1)) throw std::invalid_argument("time_step: the script has no step");
}

void validate(const MassProperties& m) {
  require_positive(m.volume, "mass_properties.volume");
  require_positive(m.mass, "mass_properties.mass");
  if (!m.com.allFinite()) throw std::invalid_argument("mass_properties.com contains NaN or infinity");
  if (!m.inertia.allFinite()) throw std::invalid_argument("mass_properties.inertia contains NaN or infinity");
  const double scale = std::max(1e-30, m.inertia.cwiseAbs().maxCoeff());
  if (!((m.inertia - m.inertia.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale))
    throw std::invalid_argument("mass_properties.inertia must be symmetric");
  const Eigen::SelfAdjointEigenSolver<Mat3> es(m.inertia);
  if (!(es.eigenvalues().minCoeff() >= -1e-9 * scale))
    throw std::invalid_argument("mass_properties.inertia must be positive semi-definite");
}

namespace {

void check_pose(const Iso3& hand_pose, const std::string& name) {
  if (!hand_pose.matrix().allFinite()) throw std::invalid_argument(name + " contains NaN or infinity");
}

}  // namespace

LiftTester::LiftTester(const HandModel& hand, const TriMesh& object, const LiftOptions& options,
                       const std::vector<Eigen::MatrixX3d>& convex_pieces, const std::optional<MassProperties>& mass)
    : impl_(std::make_unique<Impl>()) {
  validate(options);
  validate_mesh(object);
  if (mass) validate(*mass);
  if (!(options.finger_torque > 0))
    for (const Finger& f : hand.fingers())
      for (const Phalanx& p : f.phalanges)
        if (!(p.torque > 0))
          throw std::invalid_argument("hand '" + hand.name() + "' gives no torque for " + f.name + "/" + p.name +
                                      " (torque_nm in the hand file); pass finger_torque > 0");
  impl_->hand = hand;
  impl_->opt = options;
  impl_->object = physics::prepare_object(object, options, convex_pieces, mass);
}

LiftTester::~LiftTester() = default;
LiftTester::LiftTester(LiftTester&&) noexcept = default;
LiftTester& LiftTester::operator=(LiftTester&&) noexcept = default;

const LiftOptions& LiftTester::options() const { return impl_->opt; }
const MassProperties& LiftTester::mass_properties() const { return impl_->object.mass; }
LiftOptions::Shape LiftTester::shape() const { return impl_->object.shape; }
bool LiftTester::concave() const { return impl_->object.concave; }
int LiftTester::num_pieces() const { return static_cast<int>(impl_->object.pieces.size()); }

LiftResult LiftTester::run(const Iso3& hand_pose, const Eigen::VectorXd& joints, int trace_every) const {
  check_pose(hand_pose, "hand_pose");
  impl_->hand.check_joints(joints, 1e-6);
  if (trace_every < 0) throw std::invalid_argument("trace_every must be >= 0, got " + std::to_string(trace_every));
  if (trace_every == 0) return simulate(hand_pose, joints, nullptr);
  auto trace = std::make_shared<LiftTrace>();
  trace->every = trace_every;
  LiftResult r = simulate(hand_pose, joints, trace.get());
  r.trace = std::move(trace);
  return r;
}

LiftResult LiftTester::simulate(const Iso3& hand_pose, const Eigen::VectorXd& joints, LiftTrace* trace) const {
  const Impl& im = *impl_;
  const std::vector<Iso3> poses = im.hand.link_poses(hand_pose, joints);
  LiftResult res;
  res.shape = physics::shape_for_grasp(im.object, im.hand, poses);
  res.tetrahedra = res.shape == LiftOptions::Shape::Tetrahedra;
  physics::BulletWorld w(im.opt);
  btRigidBody* object = physics::add_object(w, im.object, res.shape, im.opt);
  physics::HandBodies hand = physics::add_hand(w, im.hand, hand_pose, joints, poses, im.opt);
  physics::SqueezeModel squeeze(im.hand, joints, im.opt.closing_speed, im.opt.finger_torque, im.opt.time_step,
                                  im.opt.worm_backlash);
  physics::run_script(w, object, hand, im.hand, squeeze, hand_pose, im.object.mass.com.z(), im.opt, res, trace);
  return res;
}

void LiftTester::check_batch(const std::vector<Iso3>& poses,
                             const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints) const {
  if (static_cast<Eigen::Index>(poses.size()) != joints.rows())
    throw std::invalid_argument("poses and joints have different numbers of grasps (" + std::to_string(poses.size()) +
                                " vs " + std::to_string(joints.rows()) + ")");
  for (size_t i = 0; i < poses.size(); ++i) {
    check_pose(poses[i], "hand pose " + std::to_string(i));
    impl_->hand.check_joints(joints.row(static_cast<Eigen::Index>(i)).transpose(), 1e-6,
                             ("joints[" + std::to_string(i) + "]").c_str());
  }
}

std::vector<LiftOptions::Shape> LiftTester::shapes(
    const std::vector<Iso3>& poses, const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints) const {
  check_batch(poses, joints);
  std::vector<LiftOptions::Shape> out;
  out.reserve(poses.size());
  for (size_t i = 0; i < poses.size(); ++i)
    out.push_back(physics::shape_for_grasp(
        impl_->object, impl_->hand,
        impl_->hand.link_poses(poses[i], joints.row(static_cast<Eigen::Index>(i)).transpose())));
  return out;
}

std::vector<LiftResult> LiftTester::run_batch(
    const std::vector<Iso3>& poses, const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints,
    int threads) const {
  check_batch(poses, joints);  // everything first, so that a bad row fails before any work is done
  const long n = static_cast<long>(poses.size());
  return parallel_map<LiftResult>(n, threads, 1, [&](long i) { return simulate(poses[i], joints.row(i).transpose(), nullptr); });
}

LiftResult lift_test(const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                     const TriMesh& object, const LiftOptions& options) {
  return LiftTester(hand, object, options).run(hand_pose, joints);
}

}  // namespace bayesgrasp
