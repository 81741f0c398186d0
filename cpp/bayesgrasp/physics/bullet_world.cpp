#include "bayesgrasp/physics/bullet_world.hpp"

#include <LinearMath/btConvexHullComputer.h>

namespace bayesgrasp::physics {

std::vector<btVector3> shrunk_hull(const std::vector<btVector3>& pts, double margin) {
  std::vector<btVector3> scaled(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) scaled[i] = pts[i] * btScalar(kUnit);
  btConvexHullComputer chc;
  chc.compute(&scaled[0].x(), sizeof(btVector3), static_cast<int>(scaled.size()), btScalar(kUnit * margin),
              btScalar(0.5));
  std::vector<btVector3> out;
  for (int i = 0; i < chc.vertices.size(); ++i) out.push_back(chc.vertices[i]);
  return out;
}

BulletWorld::BulletWorld(const LiftOptions& o)
    : config_(separated_pair_skip_config()),
      skip_funcs_(o.skip_separated_pairs ? make_skip_funcs() : SkipFuncs{}) {
  world_.setGravity(btVector3(0, 0, btScalar(-9.81 * kUnit)));
  world_.getSolverInfo().m_numIterations = o.solver_iterations;
  world_.getSolverInfo().m_leastSquaresResidualThreshold = btScalar(o.solver_residual);
  world_.getSolverInfo().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  world_.getSolverInfo().m_warmstartingFactor = btScalar(o.warmstart_factor);
  if (o.friction_direction_caching)
    world_.getSolverInfo().m_solverMode |=
        SOLVER_ENABLE_FRICTION_DIRECTION_CACHING | SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
}

BulletWorld::~BulletWorld() {
  for (auto& c : constraints_) world_.removeConstraint(c.get());
  for (auto& b : bodies_) world_.removeRigidBody(b.get());
}

// The hand's shapes (capsules, boxes) against the object's convex shapes go through
// SeparatedPairSkip.
BulletWorld::SkipFuncs BulletWorld::make_skip_funcs() {
  SkipFuncs fs;
  for (int h : {CAPSULE_SHAPE_PROXYTYPE, BOX_SHAPE_PROXYTYPE})
    for (int o : {CONVEX_HULL_SHAPE_PROXYTYPE, TETRAHEDRAL_SHAPE_PROXYTYPE})
      for (int swap = 0; swap < 2; ++swap) {
        const int t0 = swap ? o : h, t1 = swap ? h : o;
        fs.emplace_back(new SeparatedPairSkip::CreateFunc(config_.getCollisionAlgorithmCreateFunc(t0, t1), &skipped_));
        dispatcher_.registerCollisionCreateFunc(t0, t1, fs.back().get());
      }
  return fs;
}

btCollisionShape* BulletWorld::keep(btCollisionShape* s) {
  shapes_.emplace_back(s);
  return s;
}

btRigidBody* BulletWorld::add_body(btCollisionShape* shape, double mass, const Vec3& inertia, const btTransform& T,
                                   int group, int mask, double friction) {
  states_.emplace_back(new btDefaultMotionState(T));
  btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), states_.back().get(), shape, bt(kUnit * kUnit * inertia));
  info.m_friction = btScalar(friction);
  info.m_restitution = 0;
  bodies_.emplace_back(new btRigidBody(info));
  btRigidBody* body = bodies_.back().get();
  body->setActivationState(DISABLE_DEACTIVATION);
  world_.addRigidBody(body, group, mask);
  return body;
}

void BulletWorld::add_constraint(btTypedConstraint* c) {
  constraints_.emplace_back(c);
  world_.addConstraint(c, true);
}

}  // namespace bayesgrasp::physics
