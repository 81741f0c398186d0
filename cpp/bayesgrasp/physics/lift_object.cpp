#include "bayesgrasp/physics/lift_object.hpp"

#include <BulletCollision/CollisionShapes/btTetrahedronShape.h>
#include <BulletCollision/CollisionShapes/btTriangleCallback.h>
#include <LinearMath/btConvexHullComputer.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::physics {

namespace {

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

struct ConvexHull {
  std::vector<btVector3> vertices;
  double volume = 0.0;
  std::vector<Eigen::Vector4d> planes;  // n.x <= d, unit n
};

// Hull of a point set (Bullet's btConvexHullComputer): vertices, volume and face planes.
ConvexHull convex_hull(const std::vector<btVector3>& pts) {
  btConvexHullComputer chc;
  chc.compute(&pts[0].x(), sizeof(btVector3), static_cast<int>(pts.size()), 0, 0);
  ConvexHull h;
  for (int i = 0; i < chc.vertices.size(); ++i) h.vertices.push_back(chc.vertices[i]);
  Vec3 centre = Vec3::Zero();
  for (const btVector3& v : h.vertices) centre += eig(v);
  if (!h.vertices.empty()) centre /= static_cast<double>(h.vertices.size());
  for (int f = 0; f < chc.faces.size(); ++f) {
    const btConvexHullComputer::Edge* e0 = &chc.edges[chc.faces[f]];
    const btVector3& a = chc.vertices[e0->getSourceVertex()];
    const btConvexHullComputer::Edge* e = e0->getNextEdgeOfFace();
    Vec3 normal = Vec3::Zero();
    while (e->getTargetVertex() != e0->getSourceVertex()) {
      const btVector3& b = chc.vertices[e->getSourceVertex()];
      const btVector3& c = chc.vertices[e->getTargetVertex()];
      h.volume += a.dot(b.cross(c)) / 6.0;
      normal += eig((b - a).cross(c - a));
      e = e->getNextEdgeOfFace();
    }
    if (normal.norm() < 1e-15) continue;
    normal.normalize();
    if (normal.dot(eig(a) - centre) < 0) normal = -normal;  // outwards
    Eigen::Vector4d pl;
    pl << normal, normal.dot(eig(a));
    h.planes.push_back(pl);
  }
  h.volume = std::abs(h.volume);
  return h;
}

// Principal axes (right-handed) at the centre of mass.
void set_body_frame(LiftObject& o) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(o.mass.inertia);
  Mat3 R = es.eigenvectors();
  if (R.determinant() < 0) R.col(2) = -R.col(2);
  o.principal = es.eigenvalues().cwiseMax(1e-12);
  o.body0 = Iso3::Identity();
  o.body0.linear() = R;
  o.body0.translation() = o.mass.com;
}

// Each piece's hull in the body frame; a piece must span a volume (> 1e-12 m^3).
void add_pieces(LiftObject& o, const std::vector<Eigen::MatrixX3d>& convex_pieces, double margin) {
  if (convex_pieces.empty())
    throw std::invalid_argument("convex_pieces: the decomposition shape needs at least one convex piece");
  const Iso3 inv = o.body0.inverse();
  for (size_t i = 0; i < convex_pieces.size(); ++i) {
    const Eigen::MatrixX3d& P = convex_pieces[i];
    const std::string name = "convex_pieces[" + std::to_string(i) + "]";
    if (P.rows() < 4) throw std::invalid_argument(name + ": needs at least 4 points, got " + std::to_string(P.rows()));
    if (!P.allFinite()) throw std::invalid_argument(name + " contains NaN or infinity");
    std::vector<btVector3> pts(static_cast<size_t>(P.rows()));
    for (Eigen::Index k = 0; k < P.rows(); ++k) pts[k] = bt(Vec3(inv * Vec3(P.row(k).transpose())));
    ConvexHull h = convex_hull(pts);
    if (!(h.volume > 1e-12)) throw std::invalid_argument(name + ": spans no volume (flat or degenerate)");
    o.pieces.push_back(shrunk_hull(h.vertices, margin));
  }
}

// One tetrahedron per triangle, apex along the inward normal, cut short where the ray meets
// the opposite wall. `local`: the vertices in the body frame.
void add_tetrahedra(LiftObject& o, const TriMesh& object, const std::vector<btVector3>& local, double tet_depth) {
  const double sign = o.mass.volume > 0 ? 1.0 : -1.0;  // faces wound inwards: flip normals
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
    const btVector3 to = centroid - n * btScalar(tet_depth);
    NearestHit hit(from, to, static_cast<int>(f));
    bvh.performRaycast(&hit, from, to);
    const btScalar depth = std::max(btScalar(1e-4), hit.fraction * btScalar(tet_depth));
    const btScalar u = btScalar(kUnit);
    o.tets.push_back({a * u, b * u, c * u, (centroid - n * depth) * u});
  }
  if (o.tets.empty()) throw std::invalid_argument("mesh has only degenerate triangles");
}

}  // namespace

LiftObject prepare_object(const TriMesh& object, const LiftOptions& options,
                          const std::vector<Eigen::MatrixX3d>& convex_pieces, const std::optional<MassProperties>& mass) {
  LiftObject o;
  o.mass = mass ? *mass : bayesgrasp::mass_properties(object, options.density);  // throws if no volume
  set_body_frame(o);
  const Iso3 inv = o.body0.inverse();
  const Eigen::Index nv = object.V.rows();
  std::vector<btVector3> local(static_cast<size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) local[i] = bt(Vec3(inv * Vec3(object.V.row(i).transpose())));
  ConvexHull hull = convex_hull(local);  // also decides Auto
  o.hull = shrunk_hull(hull.vertices, options.margin);
  o.planes = std::move(hull.planes);
  o.concave = hull.volume > 1.05 * std::abs(o.mass.volume);
  o.shape = options.shape;
  if (o.shape == LiftOptions::Shape::Auto) {
    // Convex (hull within 5% of the volume): the hull. Concave: prepare the decomposition
    // (if given) or the tetrahedra, and decide per grasp.
    o.per_grasp = o.concave;
    o.shape = !o.concave ? LiftOptions::Shape::ConvexHull
              : convex_pieces.empty() ? LiftOptions::Shape::Tetrahedra
                                      : LiftOptions::Shape::Decomposition;
  }
  if (o.shape == LiftOptions::Shape::Decomposition) add_pieces(o, convex_pieces, options.margin);
  if (o.shape == LiftOptions::Shape::Tetrahedra) add_tetrahedra(o, object, local, options.tet_depth);
  return o;
}

LiftOptions::Shape shape_for_grasp(const LiftObject& o, const HandModel& hand, const std::vector<Iso3>& poses) {
  if (!o.per_grasp) return o.shape;
  // Links are sampled: capsule axes (11 points, radius added), box corners and centre, convex vertices.
  const Iso3 to_body = o.body0.inverse();
  auto depth = [&](const Vec3& p_world, double radius) {  // > 0: inside the hull by that much
    const Vec3 p = to_body * p_world;
    double d = -1e9;
    for (const auto& pl : o.planes) d = std::max(d, pl.head<3>().dot(p) - pl[3]);
    return radius - d;
  };
  for (int l = 0; l < hand.num_links(); ++l)
    for (const Shape& sh : hand.links()[l].shapes) {
      if (sh.type == Shape::Type::Capsule) {
        for (int k = 0; k <= 10; ++k)
          if (depth(poses[l] * (sh.p0 + (sh.p1 - sh.p0) * (k / 10.0)), sh.radius) > 1e-3) return o.shape;
      } else if (sh.type == Shape::Type::Convex) {
        for (const Vec3& v : sh.vertices)
          if (depth(poses[l] * v, 0.0) > 1e-3) return o.shape;
      } else {
        if (depth(poses[l] * sh.center, 0.0) > 1e-3) return o.shape;
        for (int c = 0; c < 8; ++c) {
          const Vec3 corner(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1);
          if (depth(poses[l] * (sh.center + sh.half_extents.cwiseProduct(corner)), 0.0) > 1e-3) return o.shape;
        }
      }
    }
  return LiftOptions::Shape::ConvexHull;
}

btRigidBody* add_object(BulletWorld& w, const LiftObject& o, LiftOptions::Shape shape, const LiftOptions& opt) {
  const btScalar margin = btScalar(kUnit * opt.margin);
  btTransform I;
  I.setIdentity();
  btCollisionShape* object_shape = nullptr;
  if (shape == LiftOptions::Shape::Decomposition) {
    auto* compound = static_cast<btCompoundShape*>(w.keep(new btCompoundShape(true, static_cast<int>(o.pieces.size()))));
    for (const auto& p : o.pieces) {
      auto* piece = new btConvexHullShape(&p[0].x(), static_cast<int>(p.size()), sizeof(btVector3));
      piece->setMargin(margin);
      compound->addChildShape(I, w.keep(piece));
    }
    object_shape = compound;
  } else if (shape == LiftOptions::Shape::Tetrahedra) {
    auto* compound = static_cast<btCompoundShape*>(w.keep(new btCompoundShape(true, static_cast<int>(o.tets.size()))));
    for (const auto& t : o.tets) {
      btCollisionShape* tet = w.keep(new btBU_Simplex1to4(t[0], t[1], t[2], t[3]));
      tet->setMargin(margin);
      compound->addChildShape(I, tet);
    }
    object_shape = compound;
  } else {
    auto* hull = new btConvexHullShape(&o.hull[0].x(), static_cast<int>(o.hull.size()), sizeof(btVector3));
    hull->setMargin(margin);
    object_shape = w.keep(hull);
  }
  btRigidBody* body = w.add_body(object_shape, o.mass.mass, o.principal, to_bt(o.body0), kObject, kHand | kTable, 1.0);
  if (opt.table) {
    btCollisionShape* plane = w.keep(new btStaticPlaneShape(btVector3(0, 0, 1), 0));
    w.add_body(plane, 0.0, Vec3::Zero(), I, kTable, kObject, opt.table_mu)->setUserIndex(-2);
  }
  body->setUserIndex(-1);
  return body;
}

}  // namespace bayesgrasp::physics
