#include "bayesgrasp/physics/hand_bodies.hpp"

#include <algorithm>
#include <cmath>

namespace bayesgrasp::physics {

// Up to two velocity rows along one joint axis (A's local `axis`, world = A's basis x axis):
//     w_A . axis - gain w_B . axis = rhs_i,  lambda_i in [lo_i, hi_i]
// (the constraint's world axis is recomputed each step). Set by HandBodies::apply. A `linear`
// row is the same on the bodies' linear velocities (a prismatic joint; the parent B does not
// rotate in the lift script, so its velocity at A's centre is its own).
class AngularRow : public btTypedConstraint {
 public:
  struct Row {
    btScalar rhs, lo, hi;
  };
  AngularRow(btRigidBody& a, btRigidBody& b, const btVector3& axis, bool linear = false)
      : btTypedConstraint(D6_CONSTRAINT_TYPE, a, b), axis_(axis), linear_(linear) {}
  void set(btScalar gain, std::initializer_list<Row> rows) {
    gain_ = gain;
    n_ = 0;
    for (const Row& r : rows) rows_[n_++] = r;
  }
  void clear() { n_ = 0; }
  void getInfo1(btConstraintInfo1* info) override {
    info->m_numConstraintRows = n_;
    info->nub = 0;
  }
  void getInfo2(btConstraintInfo2* info) override {
    const btVector3 ax = m_rbA.getWorldTransform().getBasis() * axis_;
    for (int i = 0; i < n_; ++i) {
      const int s = i * info->rowskip;
      for (int k = 0; k < 3; ++k) {
        (linear_ ? info->m_J1linearAxis : info->m_J1angularAxis)[s + k] = ax[k];
        (linear_ ? info->m_J2linearAxis : info->m_J2angularAxis)[s + k] = -gain_ * ax[k];
      }
      info->m_constraintError[s] = rows_[i].rhs;
      info->m_lowerLimit[s] = rows_[i].lo;
      info->m_upperLimit[s] = rows_[i].hi;
    }
  }
  void setParam(int, btScalar, int) override {}
  btScalar getParam(int, int) const override { return 0; }

 private:
  btVector3 axis_;
  bool linear_ = false;
  btScalar gain_ = 1;
  Row rows_[2];
  int n_ = 0;
};

namespace {

constexpr double kErp = 1.0;  // share of a limit's or a coupling's error corrected per step

// A compound of a link's primitives, in the link frame (placed by `T`), in Bullet units.
void add_shapes(btCompoundShape* compound, const std::vector<Shape>& shapes, const Iso3& T, double margin,
                BulletWorld& w) {
  for (const Shape& s : shapes) {
    if (s.type == Shape::Type::Box) {
      auto* box = static_cast<btBoxShape*>(w.keep(new btBoxShape(to_bt(s.half_extents))));
      box->setMargin(btScalar(kUnit * std::min(margin, s.half_extents.minCoeff())));  // inside the box
      Iso3 local = Iso3::Identity();
      local.translation() = s.center;
      compound->addChildShape(to_bt(T * local), box);
    } else if (s.type == Shape::Type::Convex) {
      // the hull shrunk by the margin, so that hull + margin is the shape's surface
      std::vector<btVector3> pts;
      for (const Vec3& v : s.vertices) pts.push_back(bt(v));
      const std::vector<btVector3> inner = shrunk_hull(pts, margin);
      auto* hull = static_cast<btConvexHullShape*>(w.keep(new btConvexHullShape(&inner[0].x(), static_cast<int>(inner.size()),
                                                                                   sizeof(btVector3))));
      hull->setMargin(btScalar(kUnit * margin));
      compound->addChildShape(to_bt(T), hull);
    } else {
      const Vec3 axis = s.p1 - s.p0;
      const double len = axis.norm();
      // A capsule is a segment with margin = radius: its surface is exact.
      auto* cap = w.keep(new btCapsuleShape(btScalar(kUnit * s.radius), btScalar(kUnit * len)));  // along local y
      Iso3 local = Iso3::Identity();
      local.translation() = 0.5 * (s.p0 + s.p1);
      if (len > 1e-12)
        local.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitY(), axis / len).toRotationMatrix();
      compound->addChildShape(to_bt(T * local), cap);
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
  btRigidBody* palm = w.add_body(palm_shape, 0.0, Vec3::Zero(), to_bt(hand_pose), kHand, kObject, o.mu);
  palm->setCollisionFlags(palm->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  return palm;
}

}  // namespace

HandBodies add_hand(BulletWorld& w, const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                    const std::vector<Iso3>& poses, const LiftOptions& o) {
  HandBodies hb;
  hb.palm = add_palm(w, hand, hand_pose, poses, o);
  hb.palm->setUserIndex(0);
  const int nj = hand.num_joints();
  hb.link_body.assign(static_cast<size_t>(hand.num_links()), hb.palm);
  hb.joint_link.assign(nj, -1);
  hb.joint_parent.assign(nj, 0);
  hb.hinge.assign(nj, nullptr);
  hb.slider.assign(nj, nullptr);
  hb.slide_origin.assign(nj, Vec3::Zero());
  hb.slide_axis.assign(nj, Vec3::Zero());
  hb.limit_row.assign(nj, nullptr);
  hb.coupling_row.assign(nj, {});
  hb.q0 = joints;
  // Hinge frames: z (Bullet's hinge axis) = minus the link's y (the joint axis). With
  // useReferenceFrameA = false Bullet's hinge angle and motor velocity then increase as the
  // finger closes (checked by the tests: free fingers close, held boxes are lifted). Closing
  // turns a phalanx about +y of its link frame (hand_model.hpp).
  Iso3 z_to_y = Iso3::Identity();
  z_to_y.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  for (const Finger& f : hand.fingers()) {
    int parent_link = 0;
    Iso3 parent_pose = hand_pose;
    for (size_t j = 0; j < f.phalanges.size(); ++j) {
      const Phalanx& ph = f.phalanges[j];
      const int k = f.first_joint + static_cast<int>(j);
      const Iso3& pose = poses[ph.link];
      auto* shape = static_cast<btCompoundShape*>(w.keep(new btCompoundShape()));
      add_shapes(shape, ph.shapes, Iso3::Identity(), o.margin, w);
      const double m = o.link_mass, L = std::max(ph.length, 0.01), r = 0.01;
      // Inertia about the link's y (its joint axis, through the centre of mass) plus the drive's
      // reflected inertia (lift_test.hpp, drive_inertia).
      btRigidBody* body = w.add_body(shape, m, Vec3(m * r * r, m * L * L / 3 + o.drive_inertia, m * L * L / 3),
                                     to_bt(pose), kHand,
                                     kObject, o.mu);
      body->setUserIndex(ph.link);
      btRigidBody* parent = hb.link_body[parent_link];
      AngularRow* limit = nullptr;
      if (ph.prismatic) {
        // A jaw: Bullet's slider along its frame's x = the link's +z (d_f, outwards), no turning.
        Iso3 z_to_x = Iso3::Identity();
        z_to_x.linear() = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitY()).toRotationMatrix();
        auto* slider = new btSliderConstraint(*parent, *body, to_bt(Iso3(parent_pose.inverse() * pose * z_to_x)),
                                              to_bt(z_to_x), true);
        slider->setLowerLinLimit(1);  // free: the limits are the limit row's
        slider->setUpperLinLimit(-1);
        slider->setLowerAngLimit(0);
        slider->setUpperAngLimit(0);
        w.add_constraint(slider);
        limit = new AngularRow(*body, *parent, btVector3(0, 0, -1), true);  // along -d_f: closing
        hb.slider[k] = slider;
        const Iso3 inv = parent_pose.inverse();
        hb.slide_origin[k] = inv * pose.translation();
        hb.slide_axis[k] = -(inv.linear() * pose.linear().col(2));
      } else {
        auto* hinge = new btHingeConstraint(*parent, *body, to_bt(Iso3(parent_pose.inverse() * pose * z_to_y)),
                                            to_bt(z_to_y), false);
        hinge->setLimit(1, -1);  // free: the limits are the limit row's
        w.add_constraint(hinge);
        limit = new AngularRow(*body, *parent, btVector3(0, 1, 0));
        hb.hinge[k] = hinge;
      }
      w.add_constraint(limit);
      hb.link_body[ph.link] = body;
      hb.joint_link[k] = ph.link;
      hb.joint_parent[k] = parent_link;
      hb.limit_row[k] = limit;
      parent_link = ph.link;
      parent_pose = pose;
    }
    // Couplings (S1): a row between every later phalanx and each phalanx that may drive it.
    for (size_t j = 1; j < f.phalanges.size(); ++j) {
      const int k = f.first_joint + static_cast<int>(j);
      for (size_t a = 0; a < j; ++a) {
        auto* row = new AngularRow(*hb.link_body[f.phalanges[j].link], *hb.link_body[f.phalanges[a].link],
                                   btVector3(0, 1, 0));
        w.add_constraint(row);
        hb.coupling_row[k].push_back(row);
      }
    }
  }
  return hb;
}

Eigen::VectorXd HandBodies::angles() const {
  Eigen::VectorXd q = q0;
  for (size_t k = 0; k < hinge.size(); ++k) {
    if (hinge[k]) q[k] = q0[k] + hinge[k]->getHingeAngle();
    if (slider[k]) {  // travel inwards since the start, from the bodies' poses
      const Iso3 P = from_bt(link_body[joint_parent[k]]->getWorldTransform());
      const Vec3 c = from_bt(link_body[joint_link[k]]->getWorldTransform().getOrigin());
      q[k] = q0[k] + (c - P * slide_origin[k]).dot(P.linear() * slide_axis[k]);
    }
  }
  return q;
}

Eigen::VectorXd HandBodies::velocities() const {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(q0.size());
  for (size_t k = 0; k < hinge.size(); ++k) {
    if (slider[k]) {
      const btRigidBody* c = link_body[joint_link[k]];
      const btRigidBody* p = link_body[joint_parent[k]];
      const Vec3 axis = from_bt(p->getWorldTransform()).linear() * slide_axis[k];
      v[k] = eig(c->getLinearVelocity() - p->getLinearVelocity()).dot(axis) / kUnit;
      continue;
    }
    if (!hinge[k]) continue;
    const btRigidBody* c = link_body[joint_link[k]];
    const btRigidBody* p = link_body[joint_parent[k]];
    const btVector3 axis = c->getWorldTransform().getBasis() * btVector3(0, 1, 0);
    v[k] = (c->getAngularVelocity() - p->getAngularVelocity()).dot(axis);
  }
  return v;
}

void HandBodies::apply(const HandModel& hand, const SqueezeModel& model, const Eigen::VectorXd& q,
                       bool couplings_changed, double time_step) {
  if (couplings_changed || q_ref_.size() == 0) q_ref_ = q;
  const btScalar fps = btScalar(1.0 / time_step), inf = SIMD_INFINITY;
  const auto& cmd = model.commands();
  for (size_t k = 0; k < hinge.size(); ++k) {
    if (!hinge[k] && !slider[k]) continue;
    const JointCommand& c = cmd[k];
    double unit = 1.0;  // rows in rad/s, or for a jaw in Bullet lengths per second
    if (slider[k]) {
      // Motor: along the slider's x (outwards), so closing is negative; force x kUnit.
      slider[k]->setPoweredLinMotor(c.driven);
      slider[k]->setTargetLinMotorVelocity(btScalar(-c.velocity * kUnit));
      slider[k]->setMaxLinMotorForce(btScalar(c.max_torque * kUnit));
      unit = kUnit;
    } else {
      // Motor: the finger's, on its driven joint only (torque in Bullet units, x kUnit^2).
      hinge[k]->enableAngularMotor(c.driven, btScalar(c.velocity),
                                   btScalar(c.max_torque * kUnit * kUnit * time_step));
    }
    // Limits as speculative rows: the joint may move up to its limit in this step, and is
    // pushed back (kErp of the error) once past it.
    auto target = [&](double limit, bool past) {
      return btScalar(unit * fps * (limit - q[k]) * (past ? kErp : 1.0));
    };
    if (c.upper - c.lower < 1e-9) {
      limit_row[k]->set(1, {{btScalar(unit * kErp * fps * (c.lower - q[k])), -inf, inf}});
    } else {
      limit_row[k]->set(1, {{target(c.lower, q[k] < c.lower), 0, inf}, {target(c.upper, q[k] > c.upper), -inf, 0}});
    }
  }
  // Couplings: w_j - G w_a = kErp fps ((G - 1)(q_a - ref_a) - sum_{a<i<=j} (q_i - ref_i)),
  // G = 1 + sum_{a<i<=j} g_i: (S1) for every coupled phalanx, in absolute angles (the palm
  // does not rotate in the script and the phalanges before a are locked).
  for (size_t f = 0; f < hand.fingers().size(); ++f) {
    const Finger& fi = hand.fingers()[f];
    const int a = model.driven(static_cast<int>(f)), ja = fi.first_joint + a;
    double G = 1.0, moved = 0.0;
    for (int j = 1; j < static_cast<int>(fi.phalanges.size()); ++j) {
      const int k = fi.first_joint + j;
      for (AngularRow* row : coupling_row[k]) row->clear();
      if (j <= a || !cmd[k].coupled) continue;
      G += cmd[k].gear_ratio;
      moved += q[k] - q_ref_[k];
      const double err = (G - 1.0) * (q[ja] - q_ref_[ja]) - moved;
      coupling_row[k][a]->set(btScalar(G), {{btScalar(kErp * fps * err), -inf, inf}});
    }
  }
}

}  // namespace bayesgrasp::physics
