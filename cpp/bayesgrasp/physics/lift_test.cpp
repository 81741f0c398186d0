#include "bayesgrasp/physics/lift_test.hpp"

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionShapes/btTetrahedronShape.h>
#include <BulletCollision/CollisionShapes/btTriangleCallback.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <LinearMath/btConvexHullComputer.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>

#include <omp.h>

namespace bayesgrasp {

namespace {

btVector3 bt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 eig(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

btTransform bt(const Iso3& T) {
  const Mat3 R = T.linear();
  btMatrix3x3 B(btScalar(R(0, 0)), btScalar(R(0, 1)), btScalar(R(0, 2)),
                btScalar(R(1, 0)), btScalar(R(1, 1)), btScalar(R(1, 2)),
                btScalar(R(2, 0)), btScalar(R(2, 1)), btScalar(R(2, 2)));
  return btTransform(B, bt(Vec3(T.translation())));
}

Iso3 eig(const btTransform& t) {
  Iso3 T = Iso3::Identity();
  const btMatrix3x3& B = t.getBasis();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = B[r][c];
  T.translation() = eig(t.getOrigin());
  return T;
}

// Collision groups: the hand touches only the object; the object the hand and the table.
constexpr int kObject = 1, kHand = 2, kTable = 4;

void check_options(const LiftOptions& o) {
  auto pos = [](double x, const char* name) {
    if (!(x > 0.0) || !std::isfinite(x))
      throw std::invalid_argument(std::string(name) + " must be positive and finite, got " + std::to_string(x));
  };
  auto nonneg = [](double x, const char* name) {
    if (!(x >= 0.0) || !std::isfinite(x))
      throw std::invalid_argument(std::string(name) + " must be >= 0 and finite, got " + std::to_string(x));
  };
  nonneg(o.mu, "mu");
  nonneg(o.table_mu, "table_mu");
  pos(o.density, "density");
  pos(o.time_step, "time_step");
  if (o.solver_iterations < 1) throw std::invalid_argument("solver_iterations must be >= 1");
  nonneg(o.squeeze_time, "squeeze_time");
  nonneg(o.lift_height, "lift_height");
  pos(o.lift_time, "lift_time");
  nonneg(o.shake_amplitude, "shake_amplitude");
  pos(o.shake_frequency, "shake_frequency");
  nonneg(o.shake_time, "shake_time");
  nonneg(o.hold_time, "hold_time");
  nonneg(o.finger_torque, "finger_torque");
  nonneg(o.closing_speed, "closing_speed");
  nonneg(o.squeeze_travel, "squeeze_travel");
  pos(o.link_mass, "link_mass");
  pos(o.success_distance, "success_distance");
  pos(o.tet_depth, "tet_depth");
  nonneg(o.margin, "margin");
}

// Nearest hit of the segment [from, to] with the mesh's triangles other than `skip`
// (Moller-Trumbore), as a fraction of the segment; 1 if none. Triangles come from the BVH.
struct NearestHit : public btTriangleCallback {
  btVector3 from, to;
  int skip;
  btScalar fraction = 1;
  NearestHit(const btVector3& f, const btVector3& t, int s) : from(f), to(t), skip(s) {}
  void processTriangle(btVector3* tri, int /*part*/, int index) override {
    if (index == skip) return;
    const btVector3 dir = to - from;
    const btVector3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
    const btVector3 p = dir.cross(e2);
    const btScalar det = e1.dot(p);
    if (std::abs(det) < btScalar(1e-12)) return;
    const btScalar inv = btScalar(1) / det;
    const btVector3 s = from - tri[0];
    const btScalar u = s.dot(p) * inv;
    if (u < 0 || u > 1) return;
    const btVector3 q = s.cross(e1);
    const btScalar v = dir.dot(q) * inv;
    if (v < 0 || u + v > 1) return;
    const btScalar t = e2.dot(q) * inv;
    if (t > 0 && t < fraction) fraction = t;
  }
};

}  // namespace

struct LiftTester::Impl {
  HandModel hand;
  LiftOptions opt;
  MassProperties mp;    // world frame
  Iso3 body0;           // object's body frame: principal axes at the centre of mass (world)
  Vec3 principal;       // principal moments
  LiftOptions::Shape shape = LiftOptions::Shape::ConvexHull;
  std::vector<btVector3> hull;                  // body frame
  std::vector<Eigen::Vector4d> planes;          // hull faces n.x <= d (body frame, unit n)
  bool concave = false;    // hull volume > 1.05 x mesh volume
  bool per_grasp = false;  // Auto on a concave object: choose per grasp (see header)
  std::vector<std::array<btVector3, 4>> tets;   // body frame
  std::vector<std::vector<btVector3>> pieces;   // hull vertices of each convex piece (body frame)
};

namespace {

// Hull vertices of a point set (Bullet's btConvexHullComputer) and the hull's volume.
std::vector<btVector3> hull_of(const std::vector<btVector3>& pts, double* volume) {
  btConvexHullComputer chc;
  chc.compute(&pts[0].x(), sizeof(btVector3), static_cast<int>(pts.size()), 0, 0);
  std::vector<btVector3> out;
  for (int i = 0; i < chc.vertices.size(); ++i) out.push_back(chc.vertices[i]);
  double vol = 0.0;
  for (int f = 0; f < chc.faces.size(); ++f) {
    const btConvexHullComputer::Edge* e0 = &chc.edges[chc.faces[f]];
    const btVector3& a = chc.vertices[e0->getSourceVertex()];
    const btConvexHullComputer::Edge* e = e0->getNextEdgeOfFace();
    while (e->getTargetVertex() != e0->getSourceVertex()) {
      vol += a.dot(chc.vertices[e->getSourceVertex()].cross(chc.vertices[e->getTargetVertex()])) / 6.0;
      e = e->getNextEdgeOfFace();
    }
  }
  *volume = std::abs(vol);
  return out;
}

}  // namespace

LiftTester::LiftTester(const HandModel& hand, const TriMesh& object, const LiftOptions& options,
                       const std::vector<Eigen::MatrixX3d>& convex_pieces)
    : impl_(std::make_unique<Impl>()) {
  check_options(options);
  validate_mesh(object);
  Impl& im = *impl_;
  im.hand = hand;
  im.opt = options;
  im.mp = bayesgrasp::mass_properties(object, options.density);  // throws if no volume
  // Principal axes (right-handed) at the centre of mass.
  Eigen::SelfAdjointEigenSolver<Mat3> es(im.mp.inertia);
  Mat3 R = es.eigenvectors();
  if (R.determinant() < 0) R.col(2) = -R.col(2);
  im.principal = es.eigenvalues().cwiseMax(1e-12);
  im.body0 = Iso3::Identity();
  im.body0.linear() = R;
  im.body0.translation() = im.mp.com;
  // Vertices in the body frame.
  const Iso3 inv = im.body0.inverse();
  const Eigen::Index nv = object.V.rows();
  std::vector<btVector3> local(static_cast<size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) local[i] = bt(Vec3(inv * Vec3(object.V.row(i).transpose())));

  // Convex hull (also decides Auto).
  btConvexHullComputer chc;
  chc.compute(&local[0].x(), sizeof(btVector3), static_cast<int>(nv), 0, 0);
  for (int i = 0; i < chc.vertices.size(); ++i) im.hull.push_back(chc.vertices[i]);
  double hull_volume = 0.0;
  Vec3 hull_centre = Vec3::Zero();
  for (const btVector3& v : im.hull) hull_centre += eig(v);
  if (!im.hull.empty()) hull_centre /= static_cast<double>(im.hull.size());
  for (int f = 0; f < chc.faces.size(); ++f) {
    const btConvexHullComputer::Edge* e0 = &chc.edges[chc.faces[f]];
    const btVector3& a = chc.vertices[e0->getSourceVertex()];
    const btConvexHullComputer::Edge* e = e0->getNextEdgeOfFace();
    Vec3 normal = Vec3::Zero();
    while (e->getTargetVertex() != e0->getSourceVertex()) {
      const btVector3& b = chc.vertices[e->getSourceVertex()];
      const btVector3& c = chc.vertices[e->getTargetVertex()];
      hull_volume += a.dot(b.cross(c)) / 6.0;
      normal += eig((b - a).cross(c - a));
      e = e->getNextEdgeOfFace();
    }
    if (normal.norm() < 1e-15) continue;
    normal.normalize();
    if (normal.dot(eig(a) - hull_centre) < 0) normal = -normal;  // outwards
    Eigen::Vector4d pl;
    pl << normal, normal.dot(eig(a));
    im.planes.push_back(pl);
  }
  hull_volume = std::abs(hull_volume);
  const double volume = std::abs(im.mp.volume);
  im.concave = hull_volume > 1.05 * volume;
  im.shape = options.shape;
  if (im.shape == LiftOptions::Shape::Auto) {
    // Convex (hull within 5% of the volume): the hull. Concave: prepare the decomposition
    // (if given) or the tetrahedra, and decide per grasp.
    im.per_grasp = im.concave;
    im.shape = !im.concave ? LiftOptions::Shape::ConvexHull
               : convex_pieces.empty() ? LiftOptions::Shape::Tetrahedra
                                       : LiftOptions::Shape::Decomposition;
  }
  if (im.shape == LiftOptions::Shape::Decomposition) {
    if (convex_pieces.empty())
      throw std::invalid_argument("convex_pieces: the decomposition shape needs at least one convex piece");
    // Each piece's hull in the body frame; a piece must span a volume (> 1e-12 m^3).
    for (size_t i = 0; i < convex_pieces.size(); ++i) {
      const Eigen::MatrixX3d& P = convex_pieces[i];
      const std::string name = "convex_pieces[" + std::to_string(i) + "]";
      if (P.rows() < 4) throw std::invalid_argument(name + ": needs at least 4 points, got " + std::to_string(P.rows()));
      if (!P.allFinite()) throw std::invalid_argument(name + " contains NaN or infinity");
      std::vector<btVector3> pts(static_cast<size_t>(P.rows()));
      for (Eigen::Index k = 0; k < P.rows(); ++k) pts[k] = bt(Vec3(inv * Vec3(P.row(k).transpose())));
      double v = 0.0;
      std::vector<btVector3> h = hull_of(pts, &v);
      if (!(v > 1e-12)) throw std::invalid_argument(name + ": spans no volume (flat or degenerate)");
      im.pieces.push_back(std::move(h));
    }
  }

  if (im.shape == LiftOptions::Shape::Tetrahedra) {
    // One tetrahedron per triangle, apex along the inward normal, cut short where the ray
    // meets the opposite wall.
    const double sign = im.mp.volume > 0 ? 1.0 : -1.0;  // faces wound inwards: flip normals
    btTriangleMesh tm(true, false);
    for (Eigen::Index f = 0; f < object.F.rows(); ++f)
      tm.addTriangle(local[object.F(f, 0)], local[object.F(f, 1)], local[object.F(f, 2)], false);
    btBvhTriangleMeshShape bvh(&tm, true);
    for (Eigen::Index f = 0; f < object.F.rows(); ++f) {
      const btVector3 a = local[object.F(f, 0)], b = local[object.F(f, 1)], c = local[object.F(f, 2)];
      btVector3 n = (b - a).cross(c - a);
      const btScalar len = n.length();
      if (len < btScalar(1e-12)) continue;  // degenerate triangle
      n *= btScalar(sign) / len;
      const btVector3 centroid = (a + b + c) / btScalar(3);
      const btVector3 from = centroid - n * btScalar(1e-6);
      const btVector3 to = centroid - n * btScalar(options.tet_depth);
      NearestHit hit(from, to, static_cast<int>(f));
      bvh.performRaycast(&hit, from, to);
      const btScalar depth = std::max(btScalar(1e-4), hit.fraction * btScalar(options.tet_depth));
      im.tets.push_back({a, b, c, centroid - n * depth});
    }
    if (im.tets.empty()) throw std::invalid_argument("mesh has only degenerate triangles");
  }
}

LiftTester::~LiftTester() = default;
LiftTester::LiftTester(LiftTester&&) noexcept = default;
LiftTester& LiftTester::operator=(LiftTester&&) noexcept = default;

const LiftOptions& LiftTester::options() const { return impl_->opt; }
const MassProperties& LiftTester::mass_properties() const { return impl_->mp; }
LiftOptions::Shape LiftTester::shape() const { return impl_->shape; }
bool LiftTester::concave() const { return impl_->concave; }
int LiftTester::num_pieces() const { return static_cast<int>(impl_->pieces.size()); }

namespace {

// Narrowphase shortcut for a convex pair that is clearly apart (a hand link and one piece of
// the object's compound, whose bounding boxes overlap but whose shapes do not touch).
// Bullet runs GJK on every child pair with overlapping boxes at every step; a finger in a
// mug overlaps most of the pieces' boxes, so ~140 GJK queries a step found no contact. This
// wrapper keeps Bullet's own algorithm (`inner`) and calls it exactly as before, except when a
// conservative bound proves that the pair is farther apart than the contact-breaking
// distance and its manifold is empty - then Bullet's algorithm would add no point either,
// so the simulation is unchanged (the skipped query has no state: Bullet's convex-convex
// algorithm builds its simplex solver anew each call).
// The bound: at a reference moment, a separating axis n (unit, from A to B) with separation
// s = min_b n.b - max_a n.a of the margin-inflated shapes. Keep n fixed in A's frame
// (n_A); A's extent along it then moves only with A's origin p_A, and B's extent changes by
// at most |m' - m| r_B, where m is n in B's frame and r_B bounds B's points about B's
// origin. So later s' >= s0 + n'.(p_B' - p_A') - |m' - m| r_B with s0 = s - n.(p_B - p_A).
class SeparatedPairSkip : public btCollisionAlgorithm {
 public:
  SeparatedPairSkip(const btCollisionAlgorithmConstructionInfo& ci, btCollisionAlgorithm* inner,
                    const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1, long* skipped)
      : btCollisionAlgorithm(ci), inner_(inner), skipped_(skipped) {
    // B: the shape with the smaller radius about its origin (the rotation term scales with it).
    const btScalar r0 = radius(w0->getCollisionShape()), r1 = radius(w1->getCollisionShape());
    b_is_0_ = r0 < r1;
    r_b_ = b_is_0_ ? r0 : r1;
  }
  ~SeparatedPairSkip() override {
    inner_->~btCollisionAlgorithm();
    m_dispatcher->freeCollisionAlgorithm(inner_);
  }

  void processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                        const btDispatcherInfo& info, btManifoldResult* out) override {
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

  btScalar calculateTimeOfImpact(btCollisionObject* b0, btCollisionObject* b1, const btDispatcherInfo& info,
                                 btManifoldResult* out) override {
    return inner_->calculateTimeOfImpact(b0, b1, info, out);
  }
  void getAllContactManifolds(btManifoldArray& ms) override { inner_->getAllContactManifolds(ms); }

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
  // Radius about the shape's origin of its margin-inflated bounding box.
  static btScalar radius(const btCollisionShape* s) {
    btTransform I;
    I.setIdentity();
    btVector3 lo, hi;
    s->getAabb(I, lo, hi);
    btVector3 c = lo.absolute();
    c.setMax(hi.absolute());
    return c.length();
  }
  // Points are added only within the contact-breaking distance; 0.1 mm of slack for GJK.
  btScalar skip_distance(const btManifoldResult* out) const {
    return manifold_->getContactBreakingThreshold() + out->m_closestPointDistanceThreshold + btScalar(1e-4);
  }
  btScalar bound(const btTransform& ta, const btTransform& tb) const {
    const btVector3 n = ta.getBasis() * n_a_;
    const btVector3 m = tb.getBasis().transpose() * n;
    return s0_ + n.dot(tb.getOrigin() - ta.getOrigin()) - (m - m_).length() * r_b_;
  }
  // Separation of the margin-inflated shapes along world axis n (unit, from A to B).
  static btScalar separation(const btConvexShape* a, const btTransform& ta, const btConvexShape* b,
                             const btTransform& tb, const btVector3& n) {
    const btVector3 pa = ta * a->localGetSupportingVertex(ta.getBasis().transpose() * n);
    const btVector3 pb = tb * b->localGetSupportingVertex(tb.getBasis().transpose() * -n);
    return n.dot(pb) - n.dot(pa);
  }
  void start(const btCollisionObjectWrapper* wa, const btCollisionObjectWrapper* wb, btScalar needed) {
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

  btCollisionAlgorithm* inner_;
  long* skipped_;
  btPersistentManifold* manifold_ = nullptr;
  bool b_is_0_ = false;
  bool tracking_ = false;
  int wait_ = 0;
  btScalar r_b_ = 0, s0_ = 0;
  btVector3 n_a_{0, 0, 0}, m_{0, 0, 0};
};

// Room in Bullet's algorithm pool for the SeparatedPairSkip wrappers.
btDefaultCollisionConstructionInfo config_info() {
  btDefaultCollisionConstructionInfo ci;
  ci.m_customCollisionAlgorithmMaxElementSize = static_cast<int>(sizeof(SeparatedPairSkip));
  return ci;
}

// Owns every Bullet object of one lift test; destroyed in reverse order of creation.
struct World {
  explicit World(bool skip_separated_pairs) : skip_funcs(skip_separated_pairs ? make_skip_funcs() : Funcs{}) {}

  btDefaultCollisionConfiguration config{config_info()};
  btCollisionDispatcher dispatcher{&config};
  // With skip_separated_pairs, the hand's shapes (capsules, boxes) against the object's
  // convex shapes go through SeparatedPairSkip (see above).
  using Funcs = std::vector<std::unique_ptr<SeparatedPairSkip::CreateFunc>>;
  long skipped = 0;  // narrowphase queries skipped
  Funcs make_skip_funcs() {
    Funcs fs;
    for (int h : {CAPSULE_SHAPE_PROXYTYPE, BOX_SHAPE_PROXYTYPE})
      for (int o : {CONVEX_HULL_SHAPE_PROXYTYPE, TETRAHEDRAL_SHAPE_PROXYTYPE})
        for (int swap = 0; swap < 2; ++swap) {
          const int t0 = swap ? o : h, t1 = swap ? h : o;
          fs.emplace_back(new SeparatedPairSkip::CreateFunc(config.getCollisionAlgorithmCreateFunc(t0, t1), &skipped));
          dispatcher.registerCollisionCreateFunc(t0, t1, fs.back().get());
        }
    return fs;
  }
  Funcs skip_funcs;
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints;

  ~World() {
    for (auto& c : constraints) world.removeConstraint(c.get());
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }

  btCollisionShape* keep(btCollisionShape* s) {
    shapes.emplace_back(s);
    return s;
  }

  btRigidBody* add_body(btCollisionShape* shape, double mass, const btVector3& inertia, const btTransform& T,
                        int group, int mask, double friction) {
    states.emplace_back(new btDefaultMotionState(T));
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), states.back().get(), shape, inertia);
    info.m_friction = btScalar(friction);
    info.m_restitution = 0;
    bodies.emplace_back(new btRigidBody(info));
    btRigidBody* body = bodies.back().get();
    body->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(body, group, mask);
    return body;
  }
};

// A compound of a link's primitives, in the link frame (optionally placed by `T`).
void add_shapes(btCompoundShape* compound, const std::vector<Shape>& shapes, const Iso3& T, double margin,
                World& w) {
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

// Palm offset (world) at time t of the script.
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

LiftResult LiftTester::run(const Iso3& hand_pose, const Eigen::VectorXd& joints) const {
  const Impl& im = *impl_;
  const LiftOptions& o = im.opt;
  if (!hand_pose.matrix().allFinite()) throw std::invalid_argument("hand_pose contains NaN or infinity");
  im.hand.check_joints(joints, 1e-6);

  World w(o.skip_separated_pairs);
  w.world.setGravity(btVector3(0, 0, btScalar(-9.81)));
  w.world.getSolverInfo().m_numIterations = o.solver_iterations;
  // friction along both tangents of every contact (see the note in lift_test.hpp)
  w.world.getSolverInfo().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  const btScalar margin = btScalar(o.margin);

  const std::vector<Iso3> poses = im.hand.link_poses(hand_pose, joints);
  LiftResult res;
  res.shape = im.shape;
  if (im.per_grasp) {
    // Auto on a concave object: the hull unless some hand link reaches more than 1 mm into
    // it (then the hand is in a concavity - a mug's opening or handle - and needs the
    // tetrahedra). Links are sampled: capsule axes (11 points, radius added), box corners
    // and centre.
    const Iso3 to_body = im.body0.inverse();
    auto depth = [&](const Vec3& p_world, double radius) {  // > 0: inside by that much
      const Vec3 p = to_body * p_world;
      double d = -1e9;
      for (const auto& pl : im.planes) d = std::max(d, pl.head<3>().dot(p) - pl[3]);
      return radius - d;
    };
    bool inside = false;
    for (int l = 0; l < im.hand.num_links() && !inside; ++l)
      for (const Shape& sh : im.hand.links()[l].shapes) {
        if (sh.type == Shape::Type::Capsule) {
          for (int k = 0; k <= 10 && !inside; ++k)
            inside = depth(poses[l] * (sh.p0 + (sh.p1 - sh.p0) * (k / 10.0)), sh.radius) > 1e-3;
        } else {
          inside = depth(poses[l] * sh.center, 0.0) > 1e-3;
          for (int c = 0; c < 8 && !inside; ++c) {
            const Vec3 corner(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1);
            inside = depth(poses[l] * (sh.center + sh.half_extents.cwiseProduct(corner)), 0.0) > 1e-3;
          }
        }
      }
    if (!inside) res.shape = LiftOptions::Shape::ConvexHull;
  }
  res.tetrahedra = res.shape == LiftOptions::Shape::Tetrahedra;

  // Object.
  btCollisionShape* object_shape = nullptr;
  btTransform I;
  I.setIdentity();
  if (res.shape == LiftOptions::Shape::Decomposition) {
    auto* compound = static_cast<btCompoundShape*>(w.keep(new btCompoundShape(true, static_cast<int>(im.pieces.size()))));
    for (const auto& p : im.pieces) {
      auto* piece = new btConvexHullShape(&p[0].x(), static_cast<int>(p.size()), sizeof(btVector3));
      piece->setMargin(margin);
      compound->addChildShape(I, w.keep(piece));
    }
    object_shape = compound;
  } else if (res.tetrahedra) {
    auto* compound = static_cast<btCompoundShape*>(w.keep(new btCompoundShape(true, static_cast<int>(im.tets.size()))));
    for (const auto& t : im.tets) {
      btCollisionShape* tet = w.keep(new btBU_Simplex1to4(t[0], t[1], t[2], t[3]));
      tet->setMargin(margin);
      compound->addChildShape(I, tet);
    }
    object_shape = compound;
  } else {
    auto* hull = new btConvexHullShape(&im.hull[0].x(), static_cast<int>(im.hull.size()), sizeof(btVector3));
    hull->setMargin(margin);
    object_shape = w.keep(hull);
  }
  btRigidBody* object = w.add_body(object_shape, im.mp.mass, bt(im.principal), bt(im.body0), kObject,
                                   kHand | kTable, 1.0);

  // Table.
  if (o.table) {
    btCollisionShape* plane = w.keep(new btStaticPlaneShape(btVector3(0, 0, 1), 0));
    w.add_body(plane, 0.0, btVector3(0, 0, 0), I, kTable, kObject, o.table_mu);
  }

  // Hand: kinematic palm (palm + knuckle shapes), dynamic phalanges hinged at their joints.
  const Iso3 hand_inv = hand_pose.inverse();
  auto* palm_shape = static_cast<btCompoundShape*>(w.keep(new btCompoundShape()));
  add_shapes(palm_shape, im.hand.links()[0].shapes, Iso3::Identity(), o.margin, w);
  for (const Finger& f : im.hand.fingers())
    if (f.knuckle_link >= 0) add_shapes(palm_shape, f.knuckle_shapes, hand_inv * poses[f.knuckle_link], o.margin, w);
  btRigidBody* palm = w.add_body(palm_shape, 0.0, btVector3(0, 0, 0), bt(hand_pose), kHand, kObject, o.mu);
  palm->setCollisionFlags(palm->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  auto* palm_state = static_cast<btDefaultMotionState*>(palm->getMotionState());

  // Hinge frames: z (Bullet's hinge axis) = minus the link's y (the joint axis). With
  // useReferenceFrameA = false Bullet's hinge angle and motor velocity then increase as
  // the finger closes (checked by the tests: free fingers close, held boxes are lifted).
  Iso3 z_to_y = Iso3::Identity();
  z_to_y.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  const double dt = o.time_step;
  for (const Finger& f : im.hand.fingers()) {
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
      // Non-backdrivable (worm-driven, like the Barrett hand): the joint cannot open past
      // its closed angle, and closes at most squeeze_travel further (or to its limit).
      // Stiff limits (softness 1, bias 0.9; Bullet's defaults 0.9 / 0.3 let a pressed
      // finger give way by several degrees).
      hinge->setLimit(0, btScalar(std::max(0.0, std::min(ph.upper - q, o.squeeze_travel))), 1.0f, 0.9f);
      hinge->enableAngularMotor(true, btScalar(o.closing_speed), btScalar(o.finger_torque * dt));
      w.constraints.emplace_back(hinge);
      w.world.addConstraint(hinge, true);
      parent = body;
      parent_pose = pose;
    }
  }

  // Script.
  const double total = o.squeeze_time + o.lift_time + o.shake_time + o.hold_time;
  const int steps = static_cast<int>(std::ceil(total / dt - 1e-9));
  const int squeeze_steps = static_cast<int>(std::ceil(o.squeeze_time / dt - 1e-9));
  // Object pose relative to the palm.
  auto relative = [&](const Iso3& palm_pose) { return Iso3(palm_pose.inverse() * eig(object->getWorldTransform())); };
  const Iso3 start = relative(hand_pose);
  Iso3 ref = start;  // the reference becomes the pose after the squeeze
  auto measure = [&](const Iso3& palm_pose) {
    const Iso3 rel = relative(palm_pose);
    res.displacement = (rel.translation() - ref.translation()).norm();
    res.rotation = Eigen::AngleAxisd(ref.linear().transpose() * rel.linear()).angle();
    res.height_gain = object->getWorldTransform().getOrigin().z() - im.mp.com.z();
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
    w.world.stepSimulation(btScalar(dt), 0);
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
  res.skipped_queries = w.skipped;
  return res;
}

std::vector<LiftResult> LiftTester::run_batch(
    const std::vector<Iso3>& poses, const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints,
    int threads) const {
  if (static_cast<Eigen::Index>(poses.size()) != joints.rows())
    throw std::invalid_argument("poses and joints have different numbers of grasps (" + std::to_string(poses.size()) +
                                " vs " + std::to_string(joints.rows()) + ")");
  const long n = static_cast<long>(poses.size());
  // Validate everything first, so that a bad row fails before any work is done.
  for (long i = 0; i < n; ++i) {
    if (!poses[i].matrix().allFinite())
      throw std::invalid_argument("hand pose " + std::to_string(i) + " contains NaN or infinity");
    impl_->hand.check_joints(joints.row(i).transpose(), 1e-6);
  }
  std::vector<LiftResult> out(poses.size());
  std::exception_ptr error;
  const int nt = threads > 0 ? threads : omp_get_num_procs();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (long i = 0; i < n; ++i) {
    try {
      out[i] = run(poses[i], joints.row(i).transpose());
    } catch (...) {
#pragma omp critical(bg_physics_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  return out;
}

LiftResult lift_test(const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                     const TriMesh& object, const LiftOptions& options) {
  return LiftTester(hand, object, options).run(hand_pose, joints);
}

}  // namespace bayesgrasp
