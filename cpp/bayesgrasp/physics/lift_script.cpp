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

// Which hand links touch the object (a contact point with a normal impulse in the last step, or
// penetrating); and, if `trace`, every such contact as a LiftContact of sample `sample`.
void touches(BulletWorld& w, double dt, std::vector<char>& touch, LiftTrace* trace, int sample) {
  std::fill(touch.begin(), touch.end(), 0);
  btDispatcher* d = w.world().getDispatcher();
  for (int m = 0; m < d->getNumManifolds(); ++m) {
    const btPersistentManifold* pm = d->getManifoldByIndexInternal(m);
    const int i0 = pm->getBody0()->getUserIndex(), i1 = pm->getBody1()->getUserIndex();
    if (!((i0 == -1 && i1 >= 0) || (i1 == -1 && i0 >= 0))) continue;  // object - hand link only
    const int link = i0 >= 0 ? i0 : i1;
    const double sign = i1 == -1 ? 1.0 : -1.0;  // Bullet's normal is on body 1, towards body 0
    for (int c = 0; c < pm->getNumContacts(); ++c) {
      const btManifoldPoint& p = pm->getContactPoint(c);
      if (!(p.getAppliedImpulse() > 0) && !(p.getDistance() < 0)) continue;
      touch[link] = 1;
      if (!trace) continue;
      LiftContact lc;
      lc.sample = sample;
      lc.link = link;
      lc.point = from_bt(i0 >= 0 ? p.getPositionWorldOnA() : p.getPositionWorldOnB());
      lc.normal = sign * eig(p.m_normalWorldOnB);
      lc.force = p.getAppliedImpulse() / dt / kUnit;  // Bullet's impulse is in kg dm/s
      trace->contacts.push_back(lc);
    }
  }
}

}  // namespace

long script_steps(const LiftOptions& o) {
  const double total = o.squeeze_time + o.lift_time + o.shake_time + o.hold_time;
  return static_cast<long>(std::ceil(total / o.time_step - 1e-9));
}

void run_script(BulletWorld& w, btRigidBody* object, HandBodies& hb, const HandModel& hand, SqueezeModel& model,
                const Iso3& hand_pose, double com_z, const LiftOptions& o, LiftResult& res, LiftTrace* trace) {
  auto* palm_state = static_cast<btDefaultMotionState*>(hb.palm->getMotionState());
  const double dt = o.time_step;
  const long steps = script_steps(o);
  const long squeeze_steps = static_cast<long>(std::ceil(o.squeeze_time / dt - 1e-9));
  const long lift_end_step = static_cast<long>(std::ceil((o.squeeze_time + o.lift_time) / dt - 1e-9));
  // The object's pose relative to the palm, and the outcome against the reference: the
  // relative pose after the squeeze (the start before it).
  auto relative = [&](const Iso3& palm_pose) { return Iso3(palm_pose.inverse() * from_bt(object->getWorldTransform())); };
  const Iso3 start = relative(hand_pose);
  Iso3 ref = start;
  Iso3 lifted_pose = start;  // the object in the palm frame at the end of the lift
  bool after_lift = false;
  auto measure = [&](const Iso3& palm_pose) {
    const Iso3 rel = relative(palm_pose);
    res.displacement = (rel.translation() - ref.translation()).norm();
    res.hold_displacement = after_lift ? (rel.translation() - lifted_pose.translation()).norm() : 0.0;
    res.rotation = Eigen::AngleAxisd(ref.linear().transpose() * rel.linear()).angle();
    res.height_gain = from_bt(object->getWorldTransform().getOrigin()).z() - com_z;
    res.finite = rel.matrix().allFinite() && std::isfinite(res.displacement);
  };
  std::vector<char> touch(static_cast<size_t>(hand.num_links()), 0);
  auto record = [&](double t, const Iso3& palm_pose, const Eigen::VectorXd& q) {
    trace->time.push_back(t);
    trace->object_pose.push_back(relative(palm_pose));
    trace->joints.push_back(q);
    Eigen::VectorXi a(static_cast<Eigen::Index>(hand.fingers().size()));
    for (Eigen::Index f = 0; f < a.size(); ++f) a[f] = model.driven(static_cast<int>(f));
    trace->driven.push_back(a);
  };
  if (trace) {
    trace->phase_ends << o.squeeze_time, o.squeeze_time + o.lift_time, o.squeeze_time + o.lift_time + o.shake_time;
    for (const Link& l : hand.links()) trace->link_names.push_back(l.name);
  }
  Eigen::VectorXd q = hb.angles();
  hb.apply(hand, model, q, true, dt);
  // An object more than this far from where it was is lost for good: stop early.
  const double lost = std::max(0.05, 2.5 * o.success_distance);
  Iso3 palm_pose = hand_pose;
  bool traced_last = false;
  for (long k = 0; k < steps; ++k) {
    const double t = (k + 1) * dt;
    palm_pose = hand_pose;
    palm_pose.translation() += palm_offset(o, t);
    palm_state->setWorldTransform(to_bt(palm_pose));
    w.world().stepSimulation(btScalar(dt), 0);
    res.steps = static_cast<int>(k + 1);
    // The squeeze model's step: contacts and joints in, motors, limits and couplings out.
    const bool sample = trace && ((k + 1) % trace->every == 0);
    touches(w, dt, touch, sample ? trace : nullptr, static_cast<int>(trace ? trace->time.size() : 0));
    q = hb.angles();
    const bool changed = model.update(q, hb.velocities(), touch);
    hb.apply(hand, model, q, changed, dt);
    if (sample) record(t, palm_pose, q);
    traced_last = sample;
    if (k + 1 == squeeze_steps) {
      ref = relative(palm_pose);
      res.squeeze_displacement = (ref.translation() - start.translation()).norm();
    }
    if (k + 1 == lift_end_step) {
      lifted_pose = relative(palm_pose);
      after_lift = true;
    }
    if ((k + 1) % 24 == 0) {
      measure(palm_pose);
      // Lost for good: left behind by the rising palm, or moved off in the hand after the lift.
      const double lag = palm_pose.translation().z() - hand_pose.translation().z() - res.height_gain;
      if (!res.finite || lag > lost || res.hold_displacement > lost) break;
    }
  }
  measure(palm_pose);
  // Came up with the hand (rose at least lift_height - success_distance) and held through the
  // shake and the hold (moved less than success_distance in the palm frame after the lift).
  res.lifted = res.finite && res.height_gain >= o.lift_height - o.success_distance &&
               res.hold_displacement < o.success_distance;
  res.skipped_queries = w.skipped_queries();
  res.breakaway.resize(static_cast<Eigen::Index>(hand.fingers().size()));
  for (Eigen::Index f = 0; f < res.breakaway.size(); ++f) res.breakaway[f] = model.driven(static_cast<int>(f));
  if (trace) {
    if (!traced_last) {  // the last step simulated is always a sample
      touches(w, dt, touch, trace, static_cast<int>(trace->time.size()));
      record(res.steps * dt, palm_pose, q);
    }
    trace->reference_pose = ref;
  }
}

}  // namespace bayesgrasp::physics
