#include "bayesgrasp/sim/link_geometry.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/RSS.h>

#include <algorithm>
#include <cmath>

namespace bayesgrasp::sim {

namespace {

using Vertices = std::vector<fcl::Vector3d>;
using Triangles = std::vector<fcl::Triangle>;

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> make_bvh(const Vertices& v, const Triangles& t) {
  auto m = std::make_shared<fcl::BVHModel<BV>>();
  m->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
  m->addSubModel(v, t);
  m->endModel();
  m->computeLocalAABB();
  return m;
}

/// A triangle BVH of the chosen bounding-volume type and the view of its arrays.
FclGeometry make_mesh_geometry(const Vertices& v, const Triangles& t, SimOptions::Bv bv, MeshView& view) {
  if (bv == SimOptions::Bv::OBBRSS) {
    auto b = make_bvh<fcl::OBBRSSd>(v, t);
    view = {b->vertices, b->tri_indices};
    return b;
  }
  auto b = make_bvh<fcl::RSSd>(v, t);
  view = {b->vertices, b->tri_indices};
  return b;
}

/// Convex tessellation of a capsule (axis z, centred, half length hl) that contains it:
/// rings of n vertices on the hemispheres and the cylinder, with radii enlarged so that the
/// polyhedron circumscribes the capsule.
void tessellate_capsule(double r, double hl, int n, int rings, Vertices& v, Triangles& t) {
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

void tessellate_box(const Vec3& h, Vertices& v, Triangles& t) {
  v.clear();
  t.clear();
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(), (i & 4 ? 1 : -1) * h.z());
  const int f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                        {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  for (auto& tri : f) t.emplace_back(tri[0], tri[1], tri[2]);
}

LinkShape capsule_shape(const Shape& s, const SimOptions& options) {
  LinkShape g;
  g.capsule = true;
  g.p0 = s.p0, g.p1 = s.p1, g.radius = s.radius;
  const Vec3 axis = s.p1 - s.p0;
  const double len = axis.norm();
  g.primitive_frame.translation() = 0.5 * (s.p0 + s.p1);
  if (len > 1e-12)
    g.primitive_frame.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis / len).toRotationMatrix();
  if (len > 1e-12) g.primitive = std::make_shared<fcl::Capsuled>(s.radius, len);
  else g.primitive = std::make_shared<fcl::Sphered>(s.radius);
  g.geometry_frame = g.primitive_frame;
  if (options.links == SimOptions::LinkGeometry::Meshes) {
    Vertices lv;
    Triangles lt;
    tessellate_capsule(s.radius, 0.5 * len, 12, 3, lv, lt);
    g.geometry = make_mesh_geometry(lv, lt, options.bv, g.mesh);
  } else if (options.links == SimOptions::LinkGeometry::Segments) {
    // the capsule's axis as a sliver triangle 1 um wide (in the shape frame, along z);
    // the radius (plus the sliver's width) is subtracted from its distances
    constexpr double w = 1e-6;
    const Vertices lv = {fcl::Vector3d(0, 0, -0.5 * len), fcl::Vector3d(0, 0, 0.5 * len), fcl::Vector3d(w, 0, 0)};
    g.geometry = make_mesh_geometry(lv, {fcl::Triangle(0, 1, 2)}, options.bv, g.mesh);
    g.offset = s.radius + w;
    g.sliver = true;
  } else {
    g.geometry = g.primitive;
  }
  g.reach = std::max(s.p0.norm(), s.p1.norm()) + s.radius;
  return g;
}

LinkShape box_shape(const Shape& s, const SimOptions& options) {
  LinkShape g;
  g.capsule = false;
  g.center = s.center, g.half_extents = s.half_extents;
  g.primitive_frame.translation() = s.center;
  g.geometry_frame = g.primitive_frame;
  g.primitive = std::make_shared<fcl::Boxd>(2.0 * s.half_extents);
  if (options.links == SimOptions::LinkGeometry::Primitives) {
    g.geometry = g.primitive;
  } else {
    Vertices lv;
    Triangles lt;
    tessellate_box(s.half_extents, lv, lt);
    g.geometry = make_mesh_geometry(lv, lt, options.bv, g.mesh);
  }
  g.reach = s.center.norm() + s.half_extents.norm();
  return g;
}

// A convex polyhedron: FCL's Convex for boolean checks (and distances with primitives), its
// triangles as a BVH otherwise.
LinkShape convex_shape(const Shape& s, const SimOptions& options) {
  LinkShape g;
  g.capsule = false;
  g.convex = true;
  g.vertices = s.vertices;
  auto verts = std::make_shared<std::vector<fcl::Vector3d>>(s.vertices.begin(), s.vertices.end());
  auto faces = std::make_shared<std::vector<int>>();
  Triangles lt;
  for (const auto& f : s.faces) {
    faces->insert(faces->end(), {3, f[0], f[1], f[2]});
    lt.emplace_back(f[0], f[1], f[2]);
  }
  g.primitive = std::make_shared<fcl::Convexd>(verts, static_cast<int>(s.faces.size()), faces);
  if (options.links == SimOptions::LinkGeometry::Primitives) g.geometry = g.primitive;
  else g.geometry = make_mesh_geometry(*verts, lt, options.bv, g.mesh);
  for (const Vec3& v : s.vertices) g.reach = std::max(g.reach, v.norm());
  return g;
}

}  // namespace

ObjectGeometry make_object_geometry(const TriMesh& object, SimOptions::Bv bv) {
  ObjectGeometry o;
  o.box = bounds(object);
  int k = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) o.dop_directions[k++] = Vec3(x, y, z).normalized();
  for (int j = 0; j < ObjectGeometry::kDop; ++j) o.dop_extent[j] = (object.V * o.dop_directions[j]).maxCoeff();
  Vertices v(object.V.rows());
  for (Eigen::Index i = 0; i < object.V.rows(); ++i) v[i] = object.V.row(i).transpose();
  Triangles t(object.F.rows());
  o.normals.resize(object.F.rows());
  // Outward normals need counter-clockwise faces; a mesh wound inwards as a whole (negative
  // signed volume) has its normals flipped.
  const double flip = mass_properties(object, 1.0).volume < 0 ? -1.0 : 1.0;
  for (Eigen::Index i = 0; i < object.F.rows(); ++i) {
    t[i] = fcl::Triangle(object.F(i, 0), object.F(i, 1), object.F(i, 2));
    const Vec3 a = v[t[i][0]], b = v[t[i][1]], c = v[t[i][2]];
    const Vec3 nrm = (b - a).cross(c - a);
    o.normals[i] = nrm.norm() > 0 ? Vec3(flip * nrm.normalized()) : Vec3::UnitZ();
  }
  o.bvh = make_mesh_geometry(v, t, bv, o.mesh);
  return o;
}

LinkShapes make_link_shapes(const HandModel& hand, const SimOptions& options) {
  LinkShapes links(hand.num_links());
  for (int l = 0; l < hand.num_links(); ++l)
    for (const Shape& s : hand.links()[l].shapes) {
      LinkShape g = s.type == Shape::Type::Capsule ? capsule_shape(s, options)
                    : s.type == Shape::Type::Box   ? box_shape(s, options)
                                                   : convex_shape(s, options);
      g.geometry->computeLocalAABB();
      g.primitive->computeLocalAABB();
      links[l].push_back(std::move(g));
    }
  return links;
}

double link_reach(const std::vector<LinkShape>& shapes) {
  double reach = 0.0;
  for (const LinkShape& s : shapes) reach = std::max(reach, s.reach);
  return reach;
}

double depth_below_palm(const HandModel& hand, const LinkShapes& links, const Eigen::VectorXd& q) {
  const std::vector<Iso3> local = hand.link_poses(Iso3::Identity(), q);
  double depth = 0.0;
  for (size_t l = 0; l < links.size(); ++l)
    for (const LinkShape& s : links[l]) {
      if (s.capsule) {
        depth = std::max(depth, std::max((local[l] * s.p0).z(), (local[l] * s.p1).z()) + s.radius);
      } else if (s.convex) {
        for (const Vec3& v : s.vertices) depth = std::max(depth, (local[l] * v).z());
      } else {
        const Vec3 c = local[l] * s.center;
        depth = std::max(depth, c.z() + (local[l].linear().row(2).cwiseAbs() * s.half_extents)(0));
      }
    }
  return depth;
}

}  // namespace bayesgrasp::sim
