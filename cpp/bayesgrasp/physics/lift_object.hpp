// The object of the lift tests, prepared once per mesh: mass properties and body frame, the
// convex hull (which also decides whether the object is concave), and the concave shapes
// (one tetrahedron per triangle, or the hulls of given convex pieces); per grasp, the shape to
// use and the object's Bullet body. See lift_test.hpp for the shapes.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <array>
#include <optional>
#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/physics/bullet_world.hpp"

namespace bayesgrasp::physics {

struct LiftObject {
  MassProperties mass;            // world frame
  Iso3 body0 = Iso3::Identity();  // body frame: principal axes at the centre of mass (world)
  Vec3 principal = Vec3::Zero();  // principal moments
  LiftOptions::Shape shape = LiftOptions::Shape::ConvexHull;  // prepared shape (never Auto)
  bool concave = false;           // hull volume > 1.05 x mesh volume
  bool per_grasp = false;         // Auto on a concave object: choose per grasp (shape_for_grasp)
  std::vector<btVector3> hull;                 // hull vertices (body frame, Bullet units, shrunk by the margin)
  std::vector<Eigen::Vector4d> planes;         // hull faces n.x <= d (body frame, unit n)
  std::vector<std::array<btVector3, 4>> tets;  // Tetrahedra (body frame, Bullet units)
  std::vector<std::vector<btVector3>> pieces;  // Decomposition: each piece's hull (body frame, Bullet units, shrunk)
};

/// Prepares the object (mesh, options and `mass` already validated); throws
/// std::invalid_argument for a mesh enclosing no volume (when `mass` is not given) or a convex
/// piece that is not finite or spans no volume. `mass`: given mass properties (world frame),
/// else the mesh's at options.density.
LiftObject prepare_object(const TriMesh& object, const LiftOptions& options,
                          const std::vector<Eigen::MatrixX3d>& convex_pieces,
                          const std::optional<MassProperties>& mass = std::nullopt);

/// The shape for one grasp (link poses in the world): the prepared shape, except that Auto on
/// a concave object uses the hull unless some hand link reaches more than 1 mm into it (then
/// the hand is in a concavity - a mug's opening or handle - and needs the concave shape).
LiftOptions::Shape shape_for_grasp(const LiftObject& object, const HandModel& hand, const std::vector<Iso3>& poses);

/// The object's dynamic body in `shape`, and the table plane when the options ask for it.
btRigidBody* add_object(BulletWorld& w, const LiftObject& object, LiftOptions::Shape shape, const LiftOptions& o);

}  // namespace bayesgrasp::physics
