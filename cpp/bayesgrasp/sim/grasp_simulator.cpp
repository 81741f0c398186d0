#include "bayesgrasp/sim/grasp_simulator.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/RSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>
#include <fcl/narrowphase/distance.h>
#include <limits>
#include <stdexcept>
#include <string>

namespace bayesgrasp {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxPhalanges = 8;
constexpr fcl::GJKSolverType kSolver = fcl::GST_INDEP;
constexpr double kEscape = 2e-3;  // trial travel of a link touching but not moving in (m)
constexpr double kSlideMargin = 2e-5;  // a sliding link stops this close to the object (m)

using Geom = std::shared_ptr<fcl::CollisionGeometryd>;

/// Link rotation of a phalanx with outward direction d (hand frame) at cumulative angle theta
/// (same convention as HandModel).
inline Mat3 link_rotation(const Vec3& d, double theta) {
  const Vec3 a = d.cross(Vec3::UnitZ());
  const Vec3 x = std::cos(theta) * d + std::sin(theta) * Vec3::UnitZ();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = a;
  R.col(2) = x.cross(a);
  return R;
}

/// Vertex and triangle arrays of an FCL triangle BVH (either bounding-volume type).
struct MeshView {
  const fcl::Vector3d* v = nullptr;
  const fcl::Triangle* t = nullptr;
};
template <class BV>
MeshView view_of(const fcl::BVHModel<BV>& m) {
  return {m.vertices, m.tri_indices};
}

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> make_bvh(const std::vector<fcl::Vector3d>& v, const std::vector<fcl::Triangle>& t) {
  auto m = std::make_shared<fcl::BVHModel<BV>>();
  m->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
  m->addSubModel(v, t);
  m->endModel();
  m->computeLocalAABB();
  return m;
}

/// Convex tessellation of a capsule (axis z, centred, half length hl) that contains it:
/// rings of n vertices on the hemispheres and the cylinder, with radii enlarged so that the
/// polyhedron circumscribes the capsule.
void tessellate_capsule(double r, double hl, int n, int rings, std::vector<fcl::Vector3d>& v,
                        std::vector<fcl::Triangle>& t) {
  // Scale so every face lies outside the sphere of radius r: 1 / (cos(pi/n) cos(pi/(4 rings))).
  const double R = r / (std::cos(M_PI / n) * std::cos(M_PI / (4.0 * rings)));
  v.clear();
  t.clear();
  // bottom pole, rings on lower cap (phi from -90 to 0), rings on upper cap (0 to 90), top pole
  v.emplace_back(0, 0, -hl - R);
  std::vector<std::pair<double, double>> rz;  // (radius, z) of each ring
  for (int k = 1; k <= rings; ++k) {
    const double phi = -M_PI / 2 + k * (M_PI / 2) / rings;
    rz.emplace_back(R * std::cos(phi), -hl + R * std::sin(phi));
  }
  for (int k = 0; k < rings; ++k) {
    const double phi = k * (M_PI / 2) / rings;
    rz.emplace_back(R * std::cos(phi), hl + R * std::sin(phi));
  }
  for (auto [rr, z] : rz)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      v.emplace_back(rr * std::cos(a), rr * std::sin(a), z);
    }
  v.emplace_back(0, 0, hl + R);
  const int nr = static_cast<int>(rz.size());
  const int top = static_cast<int>(v.size()) - 1;
  for (int i = 0; i < n; ++i) t.emplace_back(0, 1 + (i + 1) % n, 1 + i);
  for (int k = 0; k + 1 < nr; ++k)
    for (int i = 0; i < n; ++i) {
      const int a = 1 + k * n + i, b = 1 + k * n + (i + 1) % n;
      const int c = a + n, d = b + n;
      t.emplace_back(a, b, d);
      t.emplace_back(a, d, c);
    }
  const int last = 1 + (nr - 1) * n;
  for (int i = 0; i < n; ++i) t.emplace_back(top, last + i, last + (i + 1) % n);
}

void tessellate_box(const Vec3& h, std::vector<fcl::Vector3d>& v, std::vector<fcl::Triangle>& t) {
  v.clear();
  t.clear();
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(), (i & 4 ? 1 : -1) * h.z());
  const int f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                        {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  for (auto& tri : f) t.emplace_back(tri[0], tri[1], tri[2]);
}

}  // namespace

struct ShapeG {
  Geom geom;                      // for distance queries
  MeshView mesh;                  // geom's triangles when it is a BVH (warm starts), else empty
  Iso3 local = Iso3::Identity();  // geom frame in link frame
  double offset = 0.0;            // subtracted from geom distances (segment = capsule axis)
  Geom prim;                      // FCL primitive (boolean collision tests)
  Iso3 prim_local = Iso3::Identity();
  bool capsule = true;
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();  // capsule (link frame)
  double r = 0.0;
  Vec3 c = Vec3::Zero(), h = Vec3::Zero();  // box (link frame)
};

struct GraspSimulator::Impl {
  HandModel hand;
  TriMesh mesh;
  SimOptions opt;
  Geom object;
  MeshView object_mesh;
  std::vector<Vec3> normals;
  Eigen::AlignedBox3d box;
  std::vector<std::vector<ShapeG>> links;  // per link
  // per finger: bound[i][j] = largest distance of link j's points from joint i's axis
  std::vector<std::vector<std::vector<double>>> bound;
  std::vector<double> finger_reach;  // radius about the first phalanx joint
  static constexpr int kDop = 26;
  Vec3 dop_dirs[kDop];
  double dop_max[kDop];

  // ---- kinematics ----
  /// Poses of finger f's phalanges at phalanx angles q (relative), spread s.
  void finger_poses(const Iso3& H, int f, double s, const double* q, Iso3* out) const {
    const Finger& F = hand.fingers()[f];
    const Vec3 d = hand.finger_direction(f, s);
    Vec3 joint = F.base + F.knuckle_length * d;
    double theta = 0.0;
    for (size_t p = 0; p < F.phalanges.size(); ++p) {
      theta += q[p];
      Iso3 local = Iso3::Identity();
      local.linear() = link_rotation(d, theta);
      local.translation() = joint;
      out[p] = H * local;
      joint += F.phalanges[p].length * local.linear().col(0);
    }
  }

  // ---- cheap bounds ----
  double table_distance(int link, const Iso3& T) const {
    double d = kInf;
    for (const ShapeG& s : links[link]) {
      if (s.capsule) {
        d = std::min(d, std::min((T * s.p0).z(), (T * s.p1).z()) - s.r);
      } else {
        const Vec3 c = T * s.c;
        const double ext = std::abs(T.linear()(2, 0)) * s.h.x() + std::abs(T.linear()(2, 1)) * s.h.y() +
                           std::abs(T.linear()(2, 2)) * s.h.z();
        d = std::min(d, c.z() - ext);
      }
    }
    return d;
  }
  /// Lowest point of the link projected onto the table.
  Vec3 table_point(int link, const Iso3& T, bool project = true) const {
    double best = kInf;
    Vec3 p = Vec3::Zero();
    for (const ShapeG& s : links[link]) {
      if (s.capsule) {
        const Vec3 a = T * s.p0, b = T * s.p1;
        Vec3 q = std::abs(a.z() - b.z()) < 1e-9 ? Vec3(0.5 * (a + b)) : (a.z() < b.z() ? a : b);
        if (q.z() - s.r < best) best = q.z() - s.r, p = q;
      } else {
        const Mat3 R = T.linear();
        Vec3 q = T * s.c;
        for (int k = 0; k < 3; ++k) {
          const double rz = R(2, k);
          if (std::abs(rz) > 1e-9) q -= (rz > 0 ? 1.0 : -1.0) * s.h[k] * R.col(k);
        }
        if (q.z() < best) best = q.z(), p = q;
      }
    }
    if (project) p.z() = 0.0;
    return p;
  }
  /// Distance between the link's world AABB and the object's AABB (a lower bound).
  double box_distance(int link, const Iso3& T) const {
    Eigen::AlignedBox3d b;
    for (const ShapeG& s : links[link]) {
      if (s.capsule) {
        const Vec3 a = T * s.p0, c = T * s.p1;
        b.extend(a.cwiseMin(c) - Vec3::Constant(s.r));
        b.extend(a.cwiseMax(c) + Vec3::Constant(s.r));
      } else {
        const Vec3 c = T * s.c;
        const Vec3 e = T.linear().cwiseAbs() * s.h;
        b.extend(c - e);
        b.extend(c + e);
      }
    }
    const Vec3 gap = (box.min() - b.max()).cwiseMax(b.min() - box.max()).cwiseMax(0.0);
    double lb = gap.norm();
    // separating-axis bound over the object's 26-DOP (tighter than the box off its corners)
    for (int k = 0; k < kDop; ++k) {
      const Vec3& n = dop_dirs[k];
      double lo = kInf;
      for (const ShapeG& s : links[link]) {
        if (s.capsule) {
          lo = std::min(lo, std::min(n.dot(T * s.p0), n.dot(T * s.p1)) - s.r);
        } else {
          const Vec3 nl = T.linear().transpose() * n;
          lo = std::min(lo, n.dot(T * s.c) - nl.cwiseAbs().dot(s.h));
        }
      }
      lb = std::max(lb, lo - dop_max[k]);
    }
    return lb;
  }

  // ---- FCL queries ----
  struct Exact {
    double d = kInf;
    Vec3 point = Vec3::Zero(), link_point = Vec3::Zero();
    int tri = -1;
  };
  /// Outward contact normal: the direction from the object's nearest point to the link's when
  /// they are apart (at an edge or a rim the nearest triangle's face normal can be that of the
  /// wrong face: a palm resting on a cylinder's top face reported the side wall's horizontal
  /// normal at the rim), else the face normal.
  Vec3 contact_normal(const Exact& e) const {
    const Vec3 gap = e.link_point - e.point;
    if (e.d > 0.0 && gap.norm() > 1e-7) return gap.normalized();
    return normals[e.tri];
  }
  /// FCL distance from one shape to the object; `offset` (the capsule radius of a segment
  /// shape) is subtracted, and the link-side nearest point moved onto the capsule's surface.
  /// With a finite `cap`, only distances below it are searched for; kInf if there are none.
  /// FCL prunes every bounding-volume pair no nearer than its best distance so far, so starting
  /// that best at cap (+ offset) prunes more without changing the order of the traversal: when
  /// the distance is below cap, the same triangle pair and nearest points are found as without
  /// the cap (pairs pruned in addition lie at cap or farther).
  double shape_distance(const ShapeG& s, const Iso3& T, const fcl::DistanceRequestd& req, Exact* e,
                        double cap = kInf) const {
    fcl::DistanceResultd res;
    const bool capped = cap < kInf && cap + s.offset > 0.0;  // FCL stops at once on a best <= 0
    if (capped) res.min_distance = cap + s.offset;
    fcl::distance(object.get(), fcl::Transform3d::Identity(), s.geom.get(), T * s.local, req, res);
    if (capped && res.b1 == fcl::DistanceResultd::NONE) return kInf;  // nothing below cap
    const double d = res.min_distance - s.offset;
    if (e && d < e->d) {
      e->d = d;
      e->tri = static_cast<int>(res.b1);
      e->point = res.nearest_points[0];
      e->link_point = res.nearest_points[1];
      if (s.offset > 0) {
        const Vec3 g = e->point - e->link_point;
        if (g.norm() > 1e-12) e->link_point += s.offset * g.normalized();
      }
    }
    return d;
  }
  /// Exact distance (FCL, nearest points) from the link to the object; with a finite `cap`,
  /// e.d = kInf (and e.tri = -1) when the distance is not below cap.
  Exact exact_distance(int link, const Iso3& T, int& queries, double cap = kInf) const {
    Exact e;
    fcl::DistanceRequestd req(true);
    req.gjk_solver_type = kSolver;
    for (const ShapeG& s : links[link]) {
      shape_distance(s, T, req, &e, cap);
      ++queries;
    }
    return e;
  }
  /// Warm start of a link's distance queries: the nearest triangle pair (object, link mesh)
  /// of its last query, per shape.
  static constexpr int kWarmShapes = 2;
  struct Warm {
    int tri[kWarmShapes][2] = {{-1, -1}, {-1, -1}};
  };
  /// Distance from the link to the object if below `cap`, else kInf (no nearest points).
  /// With `warm`, each shape's search starts from the distance of its last nearest triangle
  /// pair (computed as FCL computes it at a leaf): FCL then prunes from the start, and returns
  /// a pair only if strictly nearer, so the distance is the same minimum over triangle pairs.
  double distance_below(int link, const Iso3& T, double cap, int& queries, Warm* warm = nullptr) const {
    fcl::DistanceRequestd req;
    req.gjk_solver_type = kSolver;
    double d = kInf;
    for (size_t k = 0; k < links[link].size(); ++k) {
      const ShapeG& s = links[link][k];
      ++queries;
      int* w = warm && k < kWarmShapes && s.mesh.t ? warm->tri[k] : nullptr;
      if (!w || w[0] < 0) {
        d = std::min(d, shape_distance_warm(s, T, req, cap, kInf, w));
        continue;
      }
      // the link mesh's frame relative to the object's (identity), as FCL forms it
      const fcl::Transform3d tf = fcl::Transform3d::Identity().inverse(Eigen::Isometry) * (T * s.local);
      const fcl::Triangle& a = object_mesh.t[w[0]];
      const fcl::Triangle& b = s.mesh.t[w[1]];
      fcl::Vector3d P, Q;
      const double start = fcl::detail::TriangleDistance<double>::triDistance(
          object_mesh.v[a[0]], object_mesh.v[a[1]], object_mesh.v[a[2]], s.mesh.v[b[0]], s.mesh.v[b[1]],
          s.mesh.v[b[2]], tf, P, Q);
      d = std::min(d, shape_distance_warm(s, T, req, cap, start, w));
    }
    return d;
  }
  /// shape_distance from a known pair distance `start` (FCL's raw distance, kInf if none);
  /// records the nearest pair in w.
  double shape_distance_warm(const ShapeG& s, const Iso3& T, const fcl::DistanceRequestd& req, double cap,
                             double start, int* w) const {
    fcl::DistanceResultd res;
    const double capped = cap < kInf && cap + s.offset > 0.0 ? cap + s.offset : kInf;
    const double preset = std::min(capped, start);
    if (preset < kInf && preset > 0.0) res.min_distance = preset;  // FCL stops at once on a best <= 0
    else if (preset <= 0.0) return start - s.offset;  // touching pair known (only when start <= 0)
    fcl::distance(object.get(), fcl::Transform3d::Identity(), s.geom.get(), T * s.local, req, res);
    double raw;
    if (res.b1 != fcl::DistanceResultd::NONE) {
      raw = res.min_distance;
      if (w) w[0] = static_cast<int>(res.b1), w[1] = static_cast<int>(res.b2);
    } else {
      raw = start;  // nothing strictly nearer than the preset
    }
    if (raw >= capped) return kInf;
    return raw - s.offset;
  }
  /// Bounds on the link-object distance for advancing: lower (for the step) and upper (for
  /// the contact decision). Uses the box distance bd when it exceeds box_skip, else FCL with
  /// an absolute error allowance a = rel_err * (a lower bound on the distance: bd, or the
  /// previous distance minus the travel since): FCL prunes bounding-volume pairs farther than
  /// the best distance so far minus a, so the true distance is at least the result minus a.
  void advance_distance(int link, const Iso3& T, double guess, double& lo, double& hi, int& queries) const {
    const double bd = box_distance(link, T);
    if (bd > opt.box_skip) {
      lo = bd;
      hi = kInf;
      return;
    }
    const double a = opt.rel_err * std::max(bd, guess);
    fcl::DistanceRequestd req(false, false, a > 0 ? 1e9 : 0.0, a);
    req.gjk_solver_type = kSolver;
    double d = kInf;
    for (const ShapeG& s : links[link]) {
      d = std::min(d, shape_distance(s, T, req, nullptr));
      ++queries;
    }
    hi = d;
    lo = d - a;
  }
  /// Boolean collision test with the primitive shapes (the GraspIt!-style reference).
  bool collides(int link, const Iso3& T, int& queries) const {
    if (box_distance(link, T) > 0.0) return false;
    fcl::CollisionRequestd req;
    req.gjk_solver_type = kSolver;
    for (const ShapeG& s : links[link]) {
      fcl::CollisionResultd res;
      fcl::collide(object.get(), fcl::Transform3d::Identity(), s.prim.get(), T * s.prim_local, req, res);
      ++queries;
      if (res.isCollision()) return true;
    }
    return false;
  }

  /// Whether the link at T penetrates the object (surface crossing, or lying inside it as
  /// judged from the nearest triangle's outward normal) or the table.
  bool penetrates(int link, const Iso3& T, int& queries) const {
    if (opt.table && table_distance(link, T) < -1e-9) return true;
    if (box_distance(link, T) > 0.0) return false;
    const Exact e = exact_distance(link, T, queries);
    if (e.d <= 0.0) return true;
    if (e.d < opt.contact_tolerance || e.tri < 0) return false;  // touching from outside
    // Inside the object: the link lies clearly behind the nearest face (the direction to it
    // is within 60 deg of the inward normal; near an edge the face normal alone is ambiguous).
    const Vec3 g = e.link_point - e.point;
    return g.dot(normals[e.tri]) < -0.5 * g.norm();
  }

  bool link_hits(int link, const Iso3& T, int& queries) const {
    if (opt.table && table_distance(link, T) < 0.0) return true;
    return collides(link, T, queries);
  }

  /// For a sliding link: blocked when it comes within kSlideMargin of the object (a
  /// distance query: FCL's boolean capsule-mesh test can miss grazing overlaps of a few
  /// micrometres that its distance query reports) or reaches the table.
  bool escape_blocked(int link, const Iso3& T, int& queries) const {
    if (opt.table && table_distance(link, T) < 0.0) return true;
    if (box_distance(link, T) > kSlideMargin) return false;
    fcl::DistanceRequestd req;
    req.gjk_solver_type = kSolver;
    for (const ShapeG& s : links[link]) {
      ++queries;
      if (shape_distance(s, T, req, nullptr) < kSlideMargin) return true;
    }
    return false;
  }

  // ---- closing ----
  struct LinkCache {
    Warm warm;
    double lo = 0.0, hi = kInf;  // object distance bounds
    double tab = kInf;           // table distance
    bool fresh = false;          // evaluated at the link's current pose
    /// (fresh only) lo is a lower bound standing in for an FCL distance not queried yet
    /// (query pruning); hi is then kInf. The link cannot touch the object (lo >= tolerance).
    bool pending = false;
    double guess = 0.0;          // a lower bound on the object distance at the current pose
  };

  bool pruning() const { return opt.prune_queries && opt.rel_err == 0.0 && hand.num_links() <= 64; }

  void evaluate(int link, const Iso3& T, LinkCache& c, int& queries) const {
    c.tab = opt.table ? table_distance(link, T) : kInf;
    c.fresh = true;
    c.pending = false;
    if (pruning()) {
      // The unpruned value is the box bound bd when bd > box_skip, else the FCL distance.
      // That FCL distance is at least max(bd, guess); while that bound reaches the contact
      // tolerance the link cannot touch, and the query waits until the step needs it
      // (resolve_pending).
      const double bd = box_distance(link, T);
      if (bd > opt.box_skip) {
        c.lo = bd, c.hi = kInf;
      } else if (std::max(bd, c.guess) >= opt.contact_tolerance) {
        c.lo = std::max(bd, c.guess), c.hi = kInf, c.pending = true;
      } else {
        c.lo = c.hi = distance_below(link, T, kInf, queries, &c.warm);
      }
      return;
    }
    advance_distance(link, T, c.guess, c.lo, c.hi, queries);
  }

  /// Query pruning. `limit` is the minimum of the step terms known so far; pending link k
  /// (cache entry *c[k]) has the term term(k, d) for object distance d (increasing in d), and
  /// inverse(k, t) is the distance giving term t. Pending links whose bound gives a term below
  /// the limit are queried, lowest bound first, each by query(k, cap) capped at the distance
  /// that would lower the limit. Returns the minimum over all terms: the same as if every
  /// pending link had been queried.
  template <class Term, class Inverse, class Query>
  static double resolve_pending(LinkCache* const* c, int count, double limit, Term term, Inverse inverse,
                                Query query) {
    uint64_t tried = 0;  // each link is queried at most once (count <= 64)
    for (;;) {
      int best = -1;
      double best_term = limit;
      for (int k = 0; k < count; ++k)
        if (!(tried >> k & 1) && c[k]->pending && term(k, c[k]->lo) < best_term) best = k, best_term = term(k, c[k]->lo);
      if (best < 0) return limit;
      tried |= uint64_t{1} << best;
      LinkCache& b = *c[best];
      // a hair above the limit's distance, so that round-off in inverse() cannot hide a term
      // equal to the limit
      const double cap = inverse(best, limit) * (1.0 + 1e-12) + 1e-12;
      const double d = query(best, cap);
      if (d < kInf) {
        b.lo = b.hi = d, b.pending = false;
        limit = std::min(limit, term(best, d));
      } else {
        b.lo = std::max(b.lo, cap);  // still pending, with a term at or above the limit
      }
    }
  }

  /// Whether phalanx j of finger f, within the tolerance of the object or the table, moves
  /// into it (the velocity of its nearest point, over the moving joints, points against the
  /// outward direction). A link whose motion separates it from a touching obstacle (e.g. a
  /// proximal capsule resting on an edge at the start and rotating away) is not stopped.
  bool approaching(int f, int j, const Iso3* T, const bool* moving, int first, const LinkCache& c,
                   int& queries) const {
    const Finger& F = hand.fingers()[f];
    const int link = F.phalanges[j].link;
    const double tol = opt.contact_tolerance;
    auto velocity = [&](const Vec3& p) {
      Vec3 v = Vec3::Zero();
      for (int i = first; i <= j; ++i)
        if (moving[i]) v += F.phalanges[i].ratio * T[i].linear().col(1).cross(p - T[i].translation());
      return v;
    };
    if (c.hi < tol) {
      const Exact e = exact_distance(link, T[j], queries);
      if (e.d < tol) {
        if (e.d <= 0.0 || e.tri < 0) return true;
        const Vec3 gap = e.link_point - e.point;
        const Vec3 n = gap.norm() > 1e-7 ? Vec3(gap.normalized()) : normals[e.tri];
        const Vec3 v = velocity(e.link_point);
        if (v.dot(n) < -0.2 * v.norm()) return true;  // clearly moving in; else checked escape
      }
    }
    if (c.tab < tol) {
      const Vec3 v = velocity(table_point(link, T[j], false));
      if (v.z() < -0.2 * v.norm()) return true;
    }
    return false;
  }

  /// Closes finger f by conservative advancement; q holds the full joint vector (in/out).
  void close_finger(const Iso3& H, int f, Eigen::VectorXd& q, std::vector<LinkCache>& cache, int& queries,
                    int& iterations) const {
    const Finger& F = hand.fingers()[f];
    const int n = static_cast<int>(F.phalanges.size());
    const double tol = opt.contact_tolerance;
    double* qf = q.data() + F.first_joint;
    bool frozen[kMaxPhalanges] = {false};
    Iso3 T[kMaxPhalanges];
    finger_poses(H, f, q[0], qf, T);
    // cull: a finger whose whole reach (a sphere about its first joint) misses the object's
    // box only sees the table
    const Vec3 j0 = H * (F.base + F.knuckle_length * hand.finger_direction(f, q[0]));
    const double gap = (box.min() - j0).cwiseMax(j0 - box.max()).cwiseMax(0.0).norm();
    const bool sees_object = gap <= finger_reach[f] + tol;
    double t = 0.0;
    for (int it = 0; it < opt.max_iterations; ++it) {
      bool moving[kMaxPhalanges];
      int first = n;
      for (int i = 0; i < n; ++i) {
        const Phalanx& P = F.phalanges[i];
        moving[i] = !frozen[i] && P.ratio > 0 && qf[i] < P.upper;
        if (moving[i] && first == n) first = i;
      }
      if (first == n) break;
      // distances of the active links (those at or after the first moving joint)
      int touching = -1;
      bool escaping[kMaxPhalanges] = {false};
      for (int j = first; j < n; ++j) {
        LinkCache& c = cache[F.phalanges[j].link];
        if (!c.fresh) {
          if (sees_object) {
            evaluate(F.phalanges[j].link, T[j], c, queries);
          } else {
            c.lo = kInf, c.hi = kInf, c.tab = opt.table ? table_distance(F.phalanges[j].link, T[j]) : kInf;
            c.fresh = true;
          }
        }
        if (c.hi < tol || c.tab < tol) {
          if (approaching(f, j, T, moving, first, c, queries)) touching = j;
          else escaping[j] = true;
        }
      }
      if (touching >= 0) {
        for (int i = 0; i <= touching; ++i) frozen[i] = true;
        continue;
      }
      // safe step in t: the minimum over the links' terms (d - tol / 2) / v, d = min(object,
      // table), and the joint limits. (min(a, b) - x) / v = min((a - x) / v, (b - x) / v)
      // exactly in floating point, so the object and table terms are taken separately: the
      // object terms of pending links are then resolved last, against the others' minimum.
      ++iterations;
      double dt = kInf, vmax = 0.0, vlink[kMaxPhalanges] = {0.0};
      bool any_escaping = false;
      LinkCache* pend[kMaxPhalanges];  // links with pending object terms
      int pend_j[kMaxPhalanges], npend = 0;
      for (int j = first; j < n; ++j) {
        double v = 0.0;
        for (int i = first; i <= j; ++i)
          if (moving[i]) v += F.phalanges[i].ratio * bound[f][i][j];
        if (v <= 0.0) continue;
        vmax = std::max(vmax, v);
        vlink[j] = v;
        LinkCache& c = cache[F.phalanges[j].link];
        if (escaping[j]) {
          // touching but not clearly moving in: try a step of kEscape travel, checked below
          any_escaping = true;
          dt = std::min(dt, kEscape / v);
        } else {
          dt = std::min(dt, (c.tab - 0.5 * tol) / v);
          if (c.pending) pend[npend] = &cache[F.phalanges[j].link], pend_j[npend++] = j;
          else dt = std::min(dt, (c.lo - 0.5 * tol) / v);
        }
      }
      for (int i = first; i < n; ++i)
        if (moving[i]) {
          const Phalanx& P = F.phalanges[i];
          dt = std::min(dt, (P.upper - P.offset) / P.ratio - t);
        }
      dt = resolve_pending(
          pend, npend, dt, [&](int k, double d) { return (d - 0.5 * tol) / vlink[pend_j[k]]; },
          [&](int k, double tt) { return tt * vlink[pend_j[k]] + 0.5 * tol; },
          [&](int k, double cap) {
            return distance_below(F.phalanges[pend_j[k]].link, T[pend_j[k]], cap, queries, &pend[k]->warm);
          });
      dt = std::max(dt, 0.0);
      auto set_t = [&](double tt) {
        for (int i = first; i < n; ++i)
          if (moving[i]) {
            const Phalanx& P = F.phalanges[i];
            qf[i] = P.offset + P.ratio * tt >= P.upper - 1e-12 ? P.upper : std::clamp(P.offset + P.ratio * tt, P.lower, P.upper);
          }
        finger_poses(H, f, q[0], qf, T);
      };
      const double t_old = t;
      t += dt;
      set_t(t);
      for (int j = first; j < n; ++j) {
        LinkCache& c = cache[F.phalanges[j].link];
        c.fresh = false;
        c.guess = std::max(0.0, c.lo - vlink[j] * dt);
      }
      if (any_escaping) {
        // The escaping links were only assumed to slide or separate: check them, and on a
        // collision find the contact by bisection (GraspIt!-style) and stop there.
        auto hit = [&]() {
          int h = -1;
          for (int j = first; j < n; ++j)
            if (escaping[j] && escape_blocked(F.phalanges[j].link, T[j], queries)) h = j;
          return h;
        };
        int h = hit();
        if (h >= 0) {
          double lo = t_old, hi = t;
          while ((hi - lo) * vmax > tol) {
            const double mid = 0.5 * (lo + hi);
            set_t(mid);
            const int hm = hit();
            if (hm >= 0) hi = mid, h = hm;
            else lo = mid;
          }
          t = lo;
          set_t(t);
          for (int i = 0; i <= h; ++i) frozen[i] = true;
        }
      }
    }
  }

  /// Final contacts at joint vector q.
  void collect_contacts(const Iso3& H, const Eigen::VectorXd& q, const std::vector<LinkCache>& cache,
                        GraspResult& r) const {
    const double tol = opt.contact_tolerance;
    const std::vector<Iso3> poses = hand.link_poses(H, q);
    const int L = hand.num_links();
    r.link_contact.assign(L, 0);
    r.table_contact.assign(L, 0);
    for (int l = 0; l < L; ++l) {
      if (links[l].empty()) continue;
      const LinkCache& c = cache[l];
      const bool known_far = c.fresh && c.lo >= tol;
      // With pruning, a lower bound carried to this pose (guess) can show the link far too,
      // and the query only looks for distances below the tolerance (the same contact when
      // there is one: see shape_distance).
      const bool prune = pruning();
      if (!known_far && !(prune && !c.fresh && c.guess >= tol)) {
        const Exact e = exact_distance(l, poses[l], r.distance_queries, prune ? tol : kInf);
        if (e.d < tol && e.tri >= 0) {
          Contact k;
          k.point = e.point;
          k.normal = contact_normal(e);
          k.link = l;
          k.penetration = std::max(0.0, -e.d);
          r.contacts.push_back(k);
          r.link_contact[l] = 1;
        }
      }
      if (opt.table) {
        const double dt = table_distance(l, poses[l]);
        if (dt < tol) {
          Contact k;
          k.point = table_point(l, poses[l]);
          k.normal = Vec3::UnitZ();
          k.link = l;
          k.penetration = std::max(0.0, -dt);
          k.on_table = true;
          r.contacts.push_back(k);
          r.table_contact[l] = 1;
        }
      }
    }
  }

  /// Closing from the open preshape; if `cache` is given, the hand is known to be free
  /// and the cache holds lower bounds (not fresh) or values at the start pose.
  GraspResult close(const Iso3& H, double spread, std::vector<LinkCache>* given, bool fixed_step,
                    double step) const {
    GraspResult r;
    r.hand_pose = H;
    r.joints = hand.coupled_joints(spread, 0.0);
    const int L = hand.num_links();
    std::vector<LinkCache> cache(L);
    if (given) {
      cache = *given;
    } else {
      const std::vector<Iso3> poses = hand.link_poses(H, r.joints);
      for (int l = 0; l < L; ++l) {
        if (links[l].empty()) continue;
        if (penetrates(l, poses[l], r.distance_queries)) {
          r.collision_at_start = true;
          r.link_contact.assign(L, 0);
          r.table_contact.assign(L, 0);
          return r;
        }
      }
    }
    for (int f = 0; f < static_cast<int>(hand.fingers().size()); ++f) {
      if (fixed_step)
        close_finger_fixed(H, f, r.joints, step, r.distance_queries, r.iterations);
      else
        close_finger(H, f, r.joints, cache, r.distance_queries, r.iterations);
    }
    if (fixed_step) cache.assign(L, LinkCache{});
    collect_contacts(H, r.joints, cache, r);
    return r;
  }

  // ---- GraspIt!-style reference ----
  bool finger_link_hits(int f, int j, const Iso3& T, int& queries) const {
    return link_hits(hand.fingers()[f].phalanges[j].link, T, queries);
  }

  void close_finger_fixed(const Iso3& H, int f, Eigen::VectorXd& q, double step, int& queries,
                          int& iterations) const {
    const Finger& F = hand.fingers()[f];
    const int n = static_cast<int>(F.phalanges.size());
    double* qf = q.data() + F.first_joint;
    bool frozen[kMaxPhalanges] = {false};
    Iso3 T[kMaxPhalanges];
    double t = 0.0;
    auto angles_at = [&](double tt, const bool* mv, double* out) {
      for (int i = 0; i < n; ++i) {
        const Phalanx& P = F.phalanges[i];
        out[i] = mv[i] ? std::clamp(P.offset + P.ratio * tt, P.lower, P.upper) : qf[i];
      }
    };
    // first hit among active links at angles a; returns the largest link index hit, or -1
    auto hit = [&](const double* a, int first) {
      finger_poses(H, f, q[0], a, T);
      int h = -1;
      for (int j = first; j < n; ++j)
        if (finger_link_hits(f, j, T[j], queries)) h = j;
      return h;
    };
    for (int it = 0; it < opt.max_iterations * 10; ++it) {
      bool moving[kMaxPhalanges];
      int first = n;
      for (int i = 0; i < n; ++i) {
        const Phalanx& P = F.phalanges[i];
        moving[i] = !frozen[i] && P.ratio > 0 && qf[i] < P.upper;
        if (moving[i] && first == n) first = i;
      }
      if (first == n) break;
      ++iterations;
      double a[kMaxPhalanges];
      const double t_new = t + step;
      angles_at(t_new, moving, a);
      const int h = hit(a, first);
      if (h < 0) {
        t = t_new;
        for (int i = 0; i < n; ++i) qf[i] = a[i];
        continue;
      }
      // bisection on [t, t_new] until the fastest link point moves less than the tolerance
      double vmax = 0.0;
      for (int j = first; j < n; ++j) {
        double v = 0.0;
        for (int i = first; i <= j; ++i)
          if (moving[i]) v += F.phalanges[i].ratio * bound[f][i][j];
        vmax = std::max(vmax, v);
      }
      double lo = t, hi = t_new;
      int hit_link = h;
      while ((hi - lo) * vmax > opt.contact_tolerance) {
        const double mid = 0.5 * (lo + hi);
        angles_at(mid, moving, a);
        const int hm = hit(a, first);
        if (hm >= 0) hi = mid, hit_link = hm;
        else lo = mid;
      }
      t = lo;
      angles_at(t, moving, a);
      for (int i = 0; i < n; ++i) qf[i] = a[i];
      for (int i = 0; i <= hit_link; ++i) frozen[i] = true;
    }
  }

  // ---- top grasps ----
  double sweep = 0.0;  // sweep_depth(), computed once
  /// Deepest point below the palm face reached by any link shape along the coupled closing
  /// path (t from 0 to the largest t_max, every 0.5 deg).
  double sweep_depth(double spread) const {
    double t_end = 0.0;
    for (const Finger& f : hand.fingers()) t_end = std::max(t_end, f.t_max());
    const int L = hand.num_links();
    const double step = 0.5 * M_PI / 180.0;
    double depth = 0.0;
    for (double t = 0.0; t <= t_end + 0.5 * step; t += step) {
      const std::vector<Iso3> local = hand.link_poses(Iso3::Identity(), hand.coupled_joints(spread, t));
      for (int l = 0; l < L; ++l)
        for (const ShapeG& sh : links[l]) {
          if (sh.capsule) {
            depth = std::max(depth, std::max((local[l] * sh.p0).z(), (local[l] * sh.p1).z()) + sh.r);
          } else {
            const Vec3 c = local[l] * sh.c;
            depth = std::max(depth, c.z() + (local[l].linear().row(2).cwiseAbs() * sh.h)(0));
          }
        }
    }
    return depth;
  }

  GraspResult top_grasp(double x, double y, double yaw, double spread, double standoff) const {
    const double tol = opt.contact_tolerance;
    const Eigen::VectorXd q0 = hand.coupled_joints(spread, 0.0);
    const int L = hand.num_links();
    // depth of the open hand below its palm face (hand +z = world -z)
    double depth = 0.0;
    {
      const std::vector<Iso3> local = hand.link_poses(Iso3::Identity(), q0);
      for (int l = 0; l < L; ++l)
        for (const ShapeG& s : links[l]) {
          if (s.capsule) {
            depth = std::max(depth, std::max((local[l] * s.p0).z(), (local[l] * s.p1).z()) + s.r);
          } else {
            const Vec3 c = local[l] * s.c;
            depth = std::max(depth, c.z() + (local[l].linear().row(2).cwiseAbs() * s.h)(0));
          }
        }
    }
    double z = std::max(box.max().z(), opt.table ? 0.0 : -kInf) + depth + 0.01;
    const double z_floor = box.min().z() - 0.5 * depth;  // without a table: give up below the object
    std::vector<LinkCache> cache(L);
    int queries = 0, iterations = 0;
    Iso3 H = HandModel::top_grasp_pose(x, y, yaw, z);
    // Link poses of the open hand relative to the palm: the descent only translates them.
    const std::vector<Iso3> local = hand.link_poses(Iso3::Identity(), q0);
    std::vector<Iso3> poses(L);
    std::vector<LinkCache*> pend;
    pend.reserve(L);
    std::vector<int> pend_l;
    pend_l.reserve(L);
    for (int it = 0; it < opt.max_iterations; ++it) {
      H = HandModel::top_grasp_pose(x, y, yaw, z);
      for (int l = 0; l < L; ++l) poses[l] = H * local[l];
      double dmin = kInf;
      bool touch = false;
      pend.clear(), pend_l.clear();
      for (int l = 0; l < L; ++l) {
        if (links[l].empty()) continue;
        evaluate(l, poses[l], cache[l], queries);
        dmin = std::min(dmin, cache[l].tab);
        if (cache[l].pending) pend.push_back(&cache[l]), pend_l.push_back(l);  // see close_finger
        else dmin = std::min(dmin, cache[l].lo);
        if (cache[l].hi < tol || cache[l].tab < tol) touch = true;
      }
      if (touch) break;
      if (!opt.table && z < z_floor) break;
      // every point moves at speed 1 along -z: a link's term is its distance itself
      dmin = resolve_pending(
          pend.data(), static_cast<int>(pend.size()), dmin, [](int, double d) { return d; },
          [](int, double d) { return d; },
          [&](int k, double cap) { return distance_below(pend_l[k], poses[pend_l[k]], cap, queries, &pend[k]->warm); });
      ++iterations;
      const double dz = std::max(dmin - 0.5 * tol, 0.0);
      z -= dz;
      for (LinkCache& c : cache) c.guess = std::max(0.0, c.lo - dz);
      if (!std::isfinite(z)) {  // nothing below (no table, object out of reach)
        z = z_floor;
      }
    }
    // Keep the closing fingers' sweep above the table (see the header).
    double raise = standoff;
    if (opt.table && opt.table_clearance >= 0.0) raise = std::max(raise, sweep + opt.table_clearance - z);
    // The descent's last distances hold at the start pose when the hand is not raised; after
    // raising it every link is evaluated again. The hand is free either way (the swept volume
    // of the descent was free).
    if (raise > 0.0) {
      z += raise;
      H = HandModel::top_grasp_pose(x, y, yaw, z);
      // every point moved by `raise`: the distances found are still lower bounds after it
      const bool carry = pruning();  // (without pruning, guess only scales rel_err: kept at 0 as before)
      for (LinkCache& c : cache) c.guess = carry && c.fresh ? std::max(0.0, c.lo - raise) : 0.0, c.fresh = false;
    }
    GraspResult r = close(H, spread, &cache, false, 0.0);
    r.distance_queries += queries;
    r.iterations += iterations;
    return r;
  }
};

// ---------------------------------------------------------------------------------------
GraspSimulator::GraspSimulator(const HandModel& hand, const TriMesh& object, const SimOptions& options)
    : impl_(std::make_unique<Impl>()) {
  validate_mesh(object);
  if (!(options.contact_tolerance > 0) || !(options.rel_err >= 0) || options.rel_err >= 1 ||
      !(options.box_skip > options.contact_tolerance))
    throw std::invalid_argument("options: need contact_tolerance > 0, rel_err in [0, 1), box_skip > contact_tolerance");
  Impl& m = *impl_;
  m.hand = hand;
  m.mesh = object;
  m.opt = options;
  m.box = bounds(object);
  {
    int k = 0;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z)
          if (x || y || z) m.dop_dirs[k++] = Vec3(x, y, z).normalized();
    for (int j = 0; j < Impl::kDop; ++j) m.dop_max[j] = (object.V * m.dop_dirs[j]).maxCoeff();
  }
  std::vector<fcl::Vector3d> v(object.V.rows());
  for (Eigen::Index i = 0; i < object.V.rows(); ++i) v[i] = object.V.row(i).transpose();
  std::vector<fcl::Triangle> t(object.F.rows());
  m.normals.resize(object.F.rows());
  // Outward normals need counter-clockwise faces; a mesh wound inwards as a whole (negative
  // signed volume) has its normals flipped.
  const double flip = mass_properties(object, 1.0).volume < 0 ? -1.0 : 1.0;
  for (Eigen::Index i = 0; i < object.F.rows(); ++i) {
    t[i] = fcl::Triangle(object.F(i, 0), object.F(i, 1), object.F(i, 2));
    const Vec3 a = v[t[i][0]], b = v[t[i][1]], c = v[t[i][2]];
    const Vec3 nrm = (b - a).cross(c - a);
    m.normals[i] = nrm.norm() > 0 ? Vec3(flip * nrm.normalized()) : Vec3::UnitZ();
  }
  if (options.bv == SimOptions::Bv::OBBRSS)
    m.object = make_bvh<fcl::OBBRSSd>(v, t), m.object_mesh = view_of(static_cast<const fcl::BVHModel<fcl::OBBRSSd>&>(*m.object));
  else
    m.object = make_bvh<fcl::RSSd>(v, t), m.object_mesh = view_of(static_cast<const fcl::BVHModel<fcl::RSSd>&>(*m.object));

  // link geometry
  m.links.resize(hand.num_links());
  std::vector<double> reach(hand.num_links(), 0.0);
  for (int l = 0; l < hand.num_links(); ++l) {
    for (const Shape& s : hand.links()[l].shapes) {
      ShapeG g;
      using LG = SimOptions::LinkGeometry;
      auto bvh = [&](const std::vector<fcl::Vector3d>& lv, const std::vector<fcl::Triangle>& lt) -> Geom {
        if (options.bv == SimOptions::Bv::OBBRSS) {
          auto b = make_bvh<fcl::OBBRSSd>(lv, lt);
          g.mesh = view_of(*b);
          return b;
        }
        auto b = make_bvh<fcl::RSSd>(lv, lt);
        g.mesh = view_of(*b);
        return b;
      };
      if (s.type == Shape::Type::Capsule) {
        g.capsule = true;
        g.p0 = s.p0, g.p1 = s.p1, g.r = s.radius;
        const Vec3 axis = s.p1 - s.p0;
        const double len = axis.norm();
        g.prim_local.translation() = 0.5 * (s.p0 + s.p1);
        if (len > 1e-12)
          g.prim_local.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis / len).toRotationMatrix();
        if (len > 1e-12) g.prim = std::make_shared<fcl::Capsuled>(s.radius, len);
        else g.prim = std::make_shared<fcl::Sphered>(s.radius);
        g.local = g.prim_local;
        if (options.links == LG::Meshes) {
          std::vector<fcl::Vector3d> lv;
          std::vector<fcl::Triangle> lt;
          tessellate_capsule(s.radius, 0.5 * len, 12, 3, lv, lt);
          g.geom = bvh(lv, lt);
        } else if (options.links == LG::Segments) {
          // the capsule's axis as a sliver triangle 1 um wide (in the shape frame, along z);
          // the radius (plus the sliver's width) is subtracted from its distances
          constexpr double w = 1e-6;
          std::vector<fcl::Vector3d> lv = {fcl::Vector3d(0, 0, -0.5 * len), fcl::Vector3d(0, 0, 0.5 * len),
                                           fcl::Vector3d(w, 0, 0)};
          g.geom = bvh(lv, {fcl::Triangle(0, 1, 2)});
          g.offset = s.radius + w;
        } else {
          g.geom = g.prim;
        }
        reach[l] = std::max(reach[l], std::max(s.p0.norm(), s.p1.norm()) + s.radius);
      } else {
        g.capsule = false;
        g.c = s.center, g.h = s.half_extents;
        g.prim_local.translation() = s.center;
        g.local = g.prim_local;
        g.prim = std::make_shared<fcl::Boxd>(2.0 * s.half_extents);
        if (options.links == LG::Primitives) {
          g.geom = g.prim;
        } else {
          std::vector<fcl::Vector3d> lv;
          std::vector<fcl::Triangle> lt;
          tessellate_box(s.half_extents, lv, lt);
          g.geom = bvh(lv, lt);
        }
        reach[l] = std::max(reach[l], s.center.norm() + s.half_extents.norm());
      }
      g.geom->computeLocalAABB();
      g.prim->computeLocalAABB();
      m.links[l].push_back(g);
    }
  }
  // The sweep's depth does not depend on the spread (a rotation about the palm normal).
  m.sweep = m.sweep_depth(hand.spread_default());
  m.bound.resize(hand.fingers().size());
  m.finger_reach.resize(hand.fingers().size());
  for (size_t f = 0; f < hand.fingers().size(); ++f) {
    const Finger& F = hand.fingers()[f];
    const int n = static_cast<int>(F.phalanges.size());
    if (n > kMaxPhalanges) throw std::invalid_argument("hand: at most 8 phalanges per finger");
    m.bound[f].assign(n, std::vector<double>(n, 0.0));
    double reach_all = 0.0;
    for (int i = 0; i < n; ++i) {
      double along = 0.0;
      for (int j = i; j < n; ++j) {
        m.bound[f][i][j] = along + reach[F.phalanges[j].link];
        along += F.phalanges[j].length;
      }
      reach_all = std::max(reach_all, m.bound[f][0][i]);
    }
    m.finger_reach[f] = reach_all;
  }
}

GraspSimulator::~GraspSimulator() = default;
GraspSimulator::GraspSimulator(GraspSimulator&&) noexcept = default;
GraspSimulator& GraspSimulator::operator=(GraspSimulator&&) noexcept = default;

const HandModel& GraspSimulator::hand() const { return impl_->hand; }
const TriMesh& GraspSimulator::object() const { return impl_->mesh; }
const SimOptions& GraspSimulator::options() const { return impl_->opt; }

namespace {
void check_pose(const Iso3& H) {
  if (!H.matrix().allFinite()) throw std::invalid_argument("hand_pose: contains NaN or infinity");
}
void check_spread(const HandModel& h, double s) {
  if (!std::isfinite(s) || s < h.spread_lower() - 1e-12 || s > h.spread_upper() + 1e-12)
    throw std::invalid_argument("spread: must lie in [" + std::to_string(h.spread_lower()) + ", " +
                                std::to_string(h.spread_upper()) + "] rad, got " + std::to_string(s));
}
}  // namespace

GraspResult GraspSimulator::close(const Iso3& hand_pose, double spread) const {
  check_pose(hand_pose);
  check_spread(impl_->hand, spread);
  return impl_->close(hand_pose, spread, nullptr, false, 0.0);
}

GraspResult GraspSimulator::close_fixed_step(const Iso3& hand_pose, double spread, double step) const {
  check_pose(hand_pose);
  check_spread(impl_->hand, spread);
  if (!(step > 0) || !std::isfinite(step)) throw std::invalid_argument("step: must be positive");
  return impl_->close(hand_pose, spread, nullptr, true, step);
}

GraspResult GraspSimulator::top_grasp(double x, double y, double yaw, double spread, double standoff) const {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw))
    throw std::invalid_argument("x, y, yaw: must be finite");
  check_spread(impl_->hand, spread);
  if (!(standoff >= 0) || !std::isfinite(standoff)) throw std::invalid_argument("standoff: must be >= 0 and finite");
  return impl_->top_grasp(x, y, yaw, spread, standoff);
}

double GraspSimulator::link_object_distance(const Iso3& hand_pose, const Eigen::VectorXd& q, int link) const {
  impl_->hand.check_joints(q, 1e-9);
  if (link < 0 || link >= impl_->hand.num_links()) throw std::invalid_argument("link: out of range");
  if (impl_->links[link].empty()) return kInf;
  const std::vector<Iso3> poses = impl_->hand.link_poses(hand_pose, q);
  int queries = 0;
  return impl_->exact_distance(link, poses[link], queries).d;
}

GraspBatch make_batch(const std::vector<GraspResult>& results, int J, int L) {
  GraspBatch b;
  const int N = static_cast<int>(results.size());
  b.num_grasps = N, b.num_joints = J, b.num_links = L;
  b.joints.resize(N, J);
  b.link_contact.setZero(N, L);
  b.table_contact.setZero(N, L);
  b.collision_at_start.resize(N);
  b.hand_poses.resize(N);
  b.offsets.assign(N + 1, 0);
  b.distance_queries.resize(N);
  for (int i = 0; i < N; ++i) b.offsets[i + 1] = b.offsets[i] + static_cast<int64_t>(results[i].contacts.size());
  b.contacts.reserve(b.offsets[N]);
  for (int i = 0; i < N; ++i) {
    const GraspResult& r = results[i];
    b.joints.row(i) = r.joints.transpose();
    for (int l = 0; l < L && l < static_cast<int>(r.link_contact.size()); ++l) {
      b.link_contact(i, l) = r.link_contact[l];
      b.table_contact(i, l) = r.table_contact[l];
    }
    b.collision_at_start[i] = r.collision_at_start;
    b.hand_poses[i] = r.hand_pose;
    b.distance_queries[i] = r.distance_queries;
    b.contacts.insert(b.contacts.end(), r.contacts.begin(), r.contacts.end());
  }
  return b;
}

namespace {
template <class F>
std::vector<GraspResult> run_parallel(int n, int threads, F&& fn) {
  std::vector<GraspResult> out(n);
  if (threads <= 0) threads = omp_get_num_procs();
  threads = std::max(1, std::min(threads, n));
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
  for (int i = 0; i < n; ++i) out[i] = fn(i);
  return out;
}
}  // namespace

GraspBatch GraspSimulator::close_batch(const std::vector<Iso3>& poses, const std::vector<double>& spreads,
                                       int threads) const {
  if (spreads.size() != poses.size() && spreads.size() != 1)
    throw std::invalid_argument("spreads: need one per pose or a single value");
  for (size_t i = 0; i < poses.size(); ++i) check_pose(poses[i]);
  for (double s : spreads) check_spread(impl_->hand, s);
  const auto results = run_parallel(static_cast<int>(poses.size()), threads, [&](int i) {
    return impl_->close(poses[i], spreads.size() == 1 ? spreads[0] : spreads[i], nullptr, false, 0.0);
  });
  return make_batch(results, impl_->hand.num_joints(), impl_->hand.num_links());
}

GraspBatch GraspSimulator::top_grasp_batch(const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& xyyaw,
                                           double spread, double standoff, int threads) const {
  if (!xyyaw.allFinite()) throw std::invalid_argument("xyyaw: contains NaN or infinity");
  check_spread(impl_->hand, spread);
  if (!(standoff >= 0) || !std::isfinite(standoff)) throw std::invalid_argument("standoff: must be >= 0 and finite");
  const auto results = run_parallel(static_cast<int>(xyyaw.rows()), threads, [&](int i) {
    return impl_->top_grasp(xyyaw(i, 0), xyyaw(i, 1), xyyaw(i, 2), spread, standoff);
  });
  return make_batch(results, impl_->hand.num_joints(), impl_->hand.num_links());
}

}  // namespace bayesgrasp
