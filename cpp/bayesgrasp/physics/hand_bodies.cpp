#include "bayesgrasp/physics/hand_bodies.hpp"

#include <algorithm>
#include <cmath>

namespace bayesgrasp::physics {

namespace {

// A compound of a link's primitives, in the link frame (placed by `T`).
void add_shapes(btCompoundShape* compound, const std::vector<Shape>& shapes, const Iso3& T, double margin,
                BulletWorld& w) {
  for (const Shape& s : shapes) {
    if (s.type == Shape::Type::Box) {
      auto* box = static_cast<btBoxShape*>(w.keep(new btBoxShape(bt(s.half_extents))));
      box->setMargin(btScalar(std::min(margin, s.half_extents.minCoeff())));
      Iso3 local = Iso3::Identity();
      local.translation() = s.center;
      compound->addChildShape(bt(T * local), box);
    } else {
      const Vec3 axis = s.p1 - s.p0;
      const double len = axis.norm();
      auto* cap = w.keep(new btCapsuleShape(btScalar(s.radius), btScalar(len)));  // along local y
      Iso3 local = Iso3::Identity();
      local.translation() = 0.5 * (s.p0 + s.p1);
      if (len > 1e-12)
        local.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitY(), axis / len).toRotationMatrix();
      compound->addChildShape(bt(T * local), cap);
    }
  }
}

// Kinematic palm: the palm's and the knuckles' shapes.
btRigidBody* add_palm(BulletWorld& w, const HandModel& hand, const Iso3& hand_pose, const std::vector<Iso3>& poses,
                      const LiftOptions& o) {
  const Iso3 hand_inv = hand_pose.inverse();
  auto* palm_shape = static_cast<btCompoundShape*>(w.keep(new btCompoundShape()));
  add_shapes(palm_shape, hand.links()[0].shapes, Iso3::Identity(), o.margin, w);
  for (const Finger& f : hand.fingers())
    if (f.knuckle_link >= 0) add_shapes(palm_shape, f.knuckle_shapes, hand_inv * poses[f.knuckle_link], o.margin, w);
  btRigidBody* palm = w.add_body(palm_shape, 0.0, btVector3(0, 0, 0), bt(hand_pose), kHand, kObject, o.mu);
  palm->setCollisionFlags(palm->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  return palm;
}

}  // namespace

btRigidBody* add_hand(BulletWorld& w, const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                      const std::vector<Iso3>& poses, const LiftOptions& o) {
  btRigidBody* palm = add_palm(w, hand, hand_pose, poses, o);
  // Hinge frames: z (Bullet's hinge axis) = minus the link's y (the joint axis). With
  // useReferenceFrameA = false Bullet's hinge angle and motor velocity then increase as the
  // finger closes (checked by the tests: free fingers close, held boxes are lifted).
  Iso3 z_to_y = Iso3::Identity();
  z_to_y.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  for (const Finger& f : hand.fingers()) {
    btRigidBody* parent = palm;
    Iso3 parent_pose = hand_pose;
    for (size_t j = 0; j < f.phalanges.size(); ++j) {
      const Phalanx& ph = f.phalanges[j];
      const Iso3& pose = poses[ph.link];
      auto* shape = static_cast<btCompoundShape*>(w.keep(new btCompoundShape()));
      add_shapes(shape, ph.shapes, Iso3::Identity(), o.margin, w);
      const double m = o.link_mass, L = std::max(ph.length, 0.01), r = 0.01;
      btRigidBody* body = w.add_body(shape, m, btVector3(btScalar(m * r * r), btScalar(m * L * L / 3), btScalar(m * L * L / 3)),
                                     bt(pose), kHand, kObject, o.mu);
      const Iso3 frame_a = parent_pose.inverse() * pose * z_to_y;
      auto* hinge = new btHingeConstraint(*parent, *body, bt(frame_a), bt(z_to_y), false);
      const double q = joints[f.first_joint + static_cast<int>(j)];
      // Non-backdrivable (worm-driven, like the Barrett hand): the joint cannot open past its
      // closed angle, and closes at most squeeze_travel further (or to its limit). Stiff
      // limits (softness 1, bias 0.9; Bullet's defaults 0.9 / 0.3 let a pressed finger give
      // way by several degrees).
      hinge->setLimit(0, btScalar(std::max(0.0, std::min(ph.upper - q, o.squeeze_travel))), 1.0f, 0.9f);
      hinge->enableAngularMotor(true, btScalar(o.closing_speed), btScalar(o.finger_torque * o.time_step));
      w.add_constraint(hinge);
      parent = body;
      parent_pose = pose;
    }
  }
  return palm;
}

}  // namespace bayesgrasp::physics
