#include "bayesgrasp/physics/separated_pair_skip.hpp"

#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>

namespace bayesgrasp::physics {

namespace {

// Radius about the shape's origin of its margin-inflated bounding box.
btScalar radius(const btCollisionShape* s) {
  btTransform I;
  I.setIdentity();
  btVector3 lo, hi;
  s->getAabb(I, lo, hi);
  btVector3 c = lo.absolute();
  c.setMax(hi.absolute());
  return c.length();
}

// Separation of the margin-inflated shapes along world axis n (unit, from A to B).
btScalar separation(const btConvexShape* a, const btTransform& ta, const btConvexShape* b, const btTransform& tb,
                    const btVector3& n) {
  const btVector3 pa = ta * a->localGetSupportingVertex(ta.getBasis().transpose() * n);
  const btVector3 pb = tb * b->localGetSupportingVertex(tb.getBasis().transpose() * -n);
  return n.dot(pb) - n.dot(pa);
}

// The closest pair GJK reports (the smallest depth).
struct Closest : public btDiscreteCollisionDetectorInterface::Result {
  btVector3 normal{0, 0, 0};
  btScalar distance = BT_LARGE_FLOAT;
  bool found = false;
  void setShapeIdentifiersA(int, int) override {}
  void setShapeIdentifiersB(int, int) override {}
  void addContactPoint(const btVector3& normal_on_b, const btVector3&, btScalar depth) override {
    if (depth < distance) {
      normal = normal_on_b;
      distance = depth;
      found = true;
    }
  }
};

}  // namespace

SeparatedPairSkip::SeparatedPairSkip(const btCollisionAlgorithmConstructionInfo& ci, btCollisionAlgorithm* inner,
                                     const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                     long* skipped)
    : btCollisionAlgorithm(ci), inner_(inner), skipped_(skipped) {
  // B: the shape with the smaller radius about its origin (the rotation term scales with it).
  const btScalar r0 = radius(w0->getCollisionShape()), r1 = radius(w1->getCollisionShape());
  b_is_0_ = r0 < r1;
  r_b_ = b_is_0_ ? r0 : r1;
}

SeparatedPairSkip::~SeparatedPairSkip() {
  inner_->~btCollisionAlgorithm();
  m_dispatcher->freeCollisionAlgorithm(inner_);
}

void SeparatedPairSkip::processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                         const btDispatcherInfo& info, btManifoldResult* out) {
  const btCollisionObjectWrapper* wa = b_is_0_ ? w1 : w0;
  const btCollisionObjectWrapper* wb = b_is_0_ ? w0 : w1;
  if (tracking_ && manifold_ && manifold_->getNumContacts() == 0) {
    if (bound(wa->getWorldTransform(), wb->getWorldTransform()) > skip_distance(out)) {
      ++*skipped_;
      return;
    }
    tracking_ = false;
  }
  inner_->processCollision(w0, w1, info, out);
  if (!manifold_) {
    btManifoldArray ms;
    inner_->getAllContactManifolds(ms);
    if (ms.size() == 1) manifold_ = ms[0];
  }
  if (!manifold_ || manifold_->getNumContacts() > 0) return;
  if (wait_ > 0) {
    --wait_;
    return;
  }
  start(wa, wb, skip_distance(out));
}

// Points are added only within the contact-breaking distance; 0.1 mm of slack for GJK.
btScalar SeparatedPairSkip::skip_distance(const btManifoldResult* out) const {
  return manifold_->getContactBreakingThreshold() + out->m_closestPointDistanceThreshold + btScalar(1e-4);
}

btScalar SeparatedPairSkip::bound(const btTransform& ta, const btTransform& tb) const {
  const btVector3 n = ta.getBasis() * n_a_;
  const btVector3 m = tb.getBasis().transpose() * n;
  return s0_ + n.dot(tb.getOrigin() - ta.getOrigin()) - (m - m_).length() * r_b_;
}

// Starts tracking a separating axis when GJK finds the pair farther apart than `needed`.
void SeparatedPairSkip::start(const btCollisionObjectWrapper* wa, const btCollisionObjectWrapper* wb, btScalar needed) {
  const auto* a = static_cast<const btConvexShape*>(wa->getCollisionShape());
  const auto* b = static_cast<const btConvexShape*>(wb->getCollisionShape());
  const btTransform& ta = wa->getWorldTransform();
  const btTransform& tb = wb->getWorldTransform();
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(a, b, &simplex, &epa);
  btGjkPairDetector::ClosestPointInput in;
  in.m_transformA = ta;
  in.m_transformB = tb;
  Closest c;
  gjk.getClosestPoints(in, c, nullptr);
  wait_ = 4;  // if this fails, the next attempt in a few steps
  if (!c.found || !(c.distance > needed)) return;
  const btScalar len = c.normal.length();
  if (!(len > btScalar(1e-6))) return;
  const btVector3 n = -c.normal / len;  // Bullet's normal points from B to A
  const btScalar s = separation(a, ta, b, tb, n);  // checked, not taken from GJK
  if (!(s > needed)) return;
  n_a_ = ta.getBasis().transpose() * n;
  m_ = tb.getBasis().transpose() * n;
  s0_ = s - n.dot(tb.getOrigin() - ta.getOrigin());
  tracking_ = true;
  wait_ = 0;
}

btDefaultCollisionConstructionInfo separated_pair_skip_config() {
  btDefaultCollisionConstructionInfo ci;
  ci.m_customCollisionAlgorithmMaxElementSize = static_cast<int>(sizeof(SeparatedPairSkip));
  return ci;
}

}  // namespace bayesgrasp::physics
