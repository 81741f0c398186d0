// Narrowphase shortcut for a convex pair that is clearly apart (a hand link and one piece of
// the object's compound, whose bounding boxes overlap but whose shapes do not touch).
//
// Bullet runs GJK at every step on every child pair whose bounding boxes overlap; with a
// finger inside a mug that is most of the pairs, nearly all of them apart. This wrapper keeps
// Bullet's own algorithm (`inner`) and calls it unchanged, except when a conservative bound
// proves that the pair is farther apart than the contact-breaking distance and its manifold is
// empty - then Bullet's algorithm would add no point either, so the simulation is unchanged
// (the skipped query has no state: Bullet's convex-convex algorithm builds its simplex solver
// anew each call).
//
// The bound: at a reference moment, a separating axis n (unit, from A to B) with separation
// s = min_b n.b - max_a n.a of the margin-inflated shapes. Keep n fixed in A's frame (n_A);
// A's extent along it then moves only with A's origin p_A, and B's extent changes by at most
// |m' - m| r_B, where m is n in B's frame and r_B bounds B's points about B's origin. So later
// s' >= s0 + n'.(p_B' - p_A') - |m' - m| r_B with s0 = s - n.(p_B - p_A).
#pragma once

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>

namespace bayesgrasp::physics {

class SeparatedPairSkip : public btCollisionAlgorithm {
 public:
  SeparatedPairSkip(const btCollisionAlgorithmConstructionInfo& ci, btCollisionAlgorithm* inner,
                    const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1, long* skipped);
  ~SeparatedPairSkip() override;

  void processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                        const btDispatcherInfo& info, btManifoldResult* out) override;
  btScalar calculateTimeOfImpact(btCollisionObject* b0, btCollisionObject* b1, const btDispatcherInfo& info,
                                 btManifoldResult* out) override {
    return inner_->calculateTimeOfImpact(b0, b1, info, out);
  }
  void getAllContactManifolds(btManifoldArray& ms) override { inner_->getAllContactManifolds(ms); }

  /// Wraps Bullet's create function for a pair of shape types.
  struct CreateFunc : public btCollisionAlgorithmCreateFunc {
    btCollisionAlgorithmCreateFunc* inner;
    long* skipped;  // counts the skipped queries
    CreateFunc(btCollisionAlgorithmCreateFunc* f, long* n) : inner(f), skipped(n) {}
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* w0,
                                                   const btCollisionObjectWrapper* w1) override {
      btCollisionAlgorithm* a = inner->CreateCollisionAlgorithm(ci, w0, w1);
      void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(SeparatedPairSkip));
      return new (mem) SeparatedPairSkip(ci, a, w0, w1, skipped);
    }
  };

 private:
  btScalar skip_distance(const btManifoldResult* out) const;
  btScalar bound(const btTransform& ta, const btTransform& tb) const;
  void start(const btCollisionObjectWrapper* wa, const btCollisionObjectWrapper* wb, btScalar needed);

  btCollisionAlgorithm* inner_;
  long* skipped_;
  btPersistentManifold* manifold_ = nullptr;
  bool b_is_0_ = false;
  bool tracking_ = false;
  int wait_ = 0;
  btScalar r_b_ = 0, s0_ = 0;
  btVector3 n_a_{0, 0, 0}, m_{0, 0, 0};
};

/// Bullet's collision configuration with room in its algorithm pool for the wrappers.
btDefaultCollisionConstructionInfo separated_pair_skip_config();

}  // namespace bayesgrasp::physics
