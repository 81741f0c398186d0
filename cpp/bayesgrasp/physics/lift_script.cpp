#include "bayesgrasp/physics/lift_script.hpp"

#include <algorithm>
#include <cmath>

namespace bayesgrasp::physics {

namespace {

// Palm offset (world) at time t of the script: 0 during the squeeze, then a cosine-profile
// rise by lift_height over lift_time, then the three-axis shake under a sin^2 envelope.
Vec3 palm_offset(const LiftOptions& o, double t) {
  Vec3 d = Vec3::Zero();
  t -= o.squeeze_time;
  if (t <= 0) return d;
  const double tau = std::min(1.0, t / o.lift_time);
  d.z() = o.lift_height * 0.5 * (1.0 - std::cos(M_PI * tau));
  t -= o.lift_time;
  if (t <= 0 || o.shake_time <= 0) return d;
  if (t < o.shake_time) {
    const double env = std::pow(std::sin(M_PI * t / o.shake_time), 2);
    const double w = 2.0 * M_PI * o.shake_frequency * t;
    for (int k = 0; k < 3; ++k) d[k] += o.shake_amplitude * env * std::sin(w + 2.0 * M_PI * k / 3.0);
  }
  return d;
}

}  // namespace

void run_script(BulletWorld& w, btRigidBody* object, btRigidBody* palm, const Iso3& hand_pose, double com_z,
                const LiftOptions& o, LiftResult& res) {
  auto* palm_state = static_cast<btDefaultMotionState*>(palm->getMotionState());
  const double dt = o.time_step;
  const double total = o.squeeze_time + o.lift_time + o.shake_time + o.hold_time;
  const int steps = static_cast<int>(std::ceil(total / dt - 1e-9));
  const int squeeze_steps = static_cast<int>(std::ceil(o.squeeze_time / dt - 1e-9));
  // The object's pose relative to the palm, and the outcome against the reference: the
  // relative pose after the squeeze (the start before it).
  auto relative = [&](const Iso3& palm_pose) { return Iso3(palm_pose.inverse() * eig(object->getWorldTransform())); };
  const Iso3 start = relative(hand_pose);
  Iso3 ref = start;
  auto measure = [&](const Iso3& palm_pose) {
    const Iso3 rel = relative(palm_pose);
    res.displacement = (rel.translation() - ref.translation()).norm();
    res.rotation = Eigen::AngleAxisd(ref.linear().transpose() * rel.linear()).angle();
    res.height_gain = object->getWorldTransform().getOrigin().z() - com_z;
    res.finite = rel.matrix().allFinite() && std::isfinite(res.displacement);
  };
  // An object more than this far from where it was is lost for good: stop early.
  const double lost = std::max(0.05, 2.5 * o.success_distance);
  Iso3 palm_pose = hand_pose;
  for (int k = 0; k < steps; ++k) {
    const double t = (k + 1) * dt;
    palm_pose = hand_pose;
    palm_pose.translation() += palm_offset(o, t);
    palm_state->setWorldTransform(bt(palm_pose));
    w.world().stepSimulation(btScalar(dt), 0);
    res.steps = k + 1;
    if (k + 1 == squeeze_steps) {
      ref = relative(palm_pose);
      res.squeeze_displacement = (ref.translation() - start.translation()).norm();
    }
    if ((k + 1) % 24 == 0) {
      measure(palm_pose);
      if (!res.finite || res.displacement > lost) break;
    }
  }
  measure(palm_pose);
  res.lifted = res.finite && res.displacement < o.success_distance;
  res.skipped_queries = w.skipped_queries();
}

}  // namespace bayesgrasp::physics
