// Geometry the simulator queries: the object as an FCL triangle BVH with outward face normals,
// its axis-aligned box and 26-DOP (for cheap lower bounds), and every hand link's collision
// shapes in three forms (the FCL geometry for distance queries, the FCL primitive for boolean
// collision checks, and the analytic capsule or box for closed-form bounds).
#pragma once

#include <fcl/geometry/collision_geometry.h>
#include <fcl/math/triangle.h>

#include <limits>
#include <memory>
#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/sim/grasp_simulator.hpp"

namespace bayesgrasp::sim {

constexpr double kInf = std::numeric_limits<double>::infinity();

using FclGeometry = std::shared_ptr<fcl::CollisionGeometryd>;

/// Vertex and triangle arrays of an FCL triangle BVH (either bounding-volume type).
struct MeshView {
  const fcl::Vector3d* vertices = nullptr;
  const fcl::Triangle* triangles = nullptr;
};

/// One collision shape of a link (a capsule, box or convex shape of the hand file), prepared for queries.
struct LinkShape {
  FclGeometry geometry;                 // for distance queries (SimOptions::links)
  MeshView mesh;                        // geometry's triangles when it is a BVH (warm starts), else empty
  Iso3 geometry_frame = Iso3::Identity();  // geometry frame in the link frame
  double offset = 0.0;                  // subtracted from geometry distances (segment: the capsule radius)
  bool sliver = false;                  // geometry is a capsule's axis as one sliver triangle (cheap queries)
  FclGeometry primitive;                // FCL capsule, sphere or box (boolean collision checks)
  Iso3 primitive_frame = Iso3::Identity();
  bool capsule = true;
  bool convex = false;                  // a convex polyhedron (vertices); neither capsule nor box
  std::vector<Vec3> vertices;           // convex: its vertices (link frame)
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();  // capsule axis end points (link frame)
  double radius = 0.0;                        // capsule radius
  Vec3 center = Vec3::Zero(), half_extents = Vec3::Zero();  // box (link frame, link axes)
  double reach = 0.0;                   // largest distance of the shape's points from the link origin
};

/// Per link, its shapes (empty for a link without collision shapes).
using LinkShapes = std::vector<std::vector<LinkShape>>;

struct ObjectGeometry {
  FclGeometry bvh;                // BVHModel<OBBRSS> or BVHModel<RSS> (SimOptions::bv)
  MeshView mesh;                  // bvh's vertices and triangles
  std::vector<Vec3> normals;      // outward unit normal per triangle
  Eigen::AlignedBox3d box;        // axis-aligned bounding box
  static constexpr int kDop = 26;
  Vec3 dop_directions[kDop];      // the 26 unit directions (x, y, z in {-1, 0, 1}, not all 0)
  double dop_extent[kDop];        // max over the vertices of direction . vertex
};

/// The object's query geometry; `mesh` must be valid (validate_mesh).
ObjectGeometry make_object_geometry(const TriMesh& mesh, SimOptions::Bv bv);

/// Every link's shapes in the representation `options.links` asks for.
LinkShapes make_link_shapes(const HandModel& hand, const SimOptions& options);

/// Largest distance of a link's points from its origin (0 for a link without shapes).
double link_reach(const std::vector<LinkShape>& shapes);

/// Depth of the hand at joints q below its palm face: the largest hand-frame z (the approach
/// axis) of any point of any link shape.
double depth_below_palm(const HandModel& hand, const LinkShapes& links, const Eigen::VectorXd& q);

}  // namespace bayesgrasp::sim
