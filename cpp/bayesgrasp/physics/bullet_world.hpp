// The Bullet world of one lift test: conversions between Eigen and Bullet, the collision
// groups, and the owner of every Bullet object (destroyed in reverse order of creation).
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/physics/lift_test.hpp"
#include "bayesgrasp/physics/separated_pair_skip.hpp"

namespace bayesgrasp::physics {

// Bullet runs in decimetres: kUnit Bullet length units per metre. Lengths (positions, shapes,
// margins) x kUnit, gravity x kUnit, inertia and torques x kUnit^2, masses, times and angles
// unchanged: the same motion, with the ~1-2 cm phalanges and their contacts at sizes where
// Bullet's absolute tolerances (GJK/EPA, penetration slop, split impulse) are small.
constexpr double kUnit = 10.0;

// Plain conversions (no unit change).
inline btVector3 bt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
inline Vec3 eig(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

// Metres <-> Bullet units: a point or length, and a pose.
inline btVector3 to_bt(const Vec3& p) { return bt(kUnit * p); }
inline Vec3 from_bt(const btVector3& p) { return eig(p) / kUnit; }

inline btTransform to_bt(const Iso3& T) {
  const Mat3 R = T.linear();
  btMatrix3x3 B(btScalar(R(0, 0)), btScalar(R(0, 1)), btScalar(R(0, 2)),
                btScalar(R(1, 0)), btScalar(R(1, 1)), btScalar(R(1, 2)),
                btScalar(R(2, 0)), btScalar(R(2, 1)), btScalar(R(2, 2)));
  return btTransform(B, to_bt(Vec3(T.translation())));
}

/// A convex hull for Bullet: the points (m) in Bullet units, the hull shrunk by the collision
/// margin (each face moved inwards by `margin`, btConvexHullComputer's shrink; at most half the
/// hull's inner radius), so that hull + margin is the true surface.
std::vector<btVector3> shrunk_hull(const std::vector<btVector3>& pts, double margin);

inline Iso3 from_bt(const btTransform& t) {
  Iso3 T = Iso3::Identity();
  const btMatrix3x3& B = t.getBasis();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = B[r][c];
  T.translation() = from_bt(t.getOrigin());
  return T;
}

// Collision groups: the hand touches only the object; the object the hand and the table.
constexpr int kObject = 1, kHand = 2, kTable = 4;

/// Owns every Bullet object of one lift test. Gravity -9.81 m/s^2 along z (x kUnit), the options'
/// solver iterations, friction along both tangents of every contact (see lift_test.hpp).
class BulletWorld {
 public:
  explicit BulletWorld(const LiftOptions& options);
  ~BulletWorld();
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  btDiscreteDynamicsWorld& world() { return world_; }
  /// Takes ownership of a shape and returns it.
  btCollisionShape* keep(btCollisionShape* s);
  /// A body of `mass` kg with principal moments `inertia` (kg m^2, scaled here) at `T`
  /// (Bullet units).
  btRigidBody* add_body(btCollisionShape* shape, double mass, const Vec3& inertia, const btTransform& T,
                        int group, int mask, double friction);
  /// Takes ownership of a constraint and adds it (collisions between its bodies disabled).
  void add_constraint(btTypedConstraint* c);
  /// Narrowphase queries skipped so far (LiftOptions::skip_separated_pairs).
  long skipped_queries() const { return skipped_; }

 private:
  using SkipFuncs = std::vector<std::unique_ptr<SeparatedPairSkip::CreateFunc>>;
  SkipFuncs make_skip_funcs();

  long skipped_ = 0;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_{&config_};
  SkipFuncs skip_funcs_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_{&dispatcher_, &broadphase_, &solver_, &config_};
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btMotionState>> states_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
};

}  // namespace bayesgrasp::physics
