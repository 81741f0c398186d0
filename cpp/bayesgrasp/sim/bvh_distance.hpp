// FCL's distance between the object's BVH and a link's, with a tolerance on ties.
//
// FCL 0.7 reads a mesh-mesh traversal's rel_err and abs_err from a default request when the
// node is constructed (both 0), so a DistanceRequest's allowances never reach the traversal.
// A node prunes a bounding-volume pair only when its lower bound c satisfies
//     c >= best - abs_err  and  c (1 + rel_err) >= best.
// With both 0, a link lying parallel to a finely tessellated flat face is equally near every
// triangle under it: their bounds equal the best distance up to round-off, half of them fail
// c >= best, and the traversal visits each one (the cost of a query then grows with the
// tessellation: 494 bounding-volume tests for a 5 cm finger 0.1 mm from a face of a 49k-triangle
// box, against 62 with the tolerance below).
// bvh_distance sets the node up as fcl::distance does and writes the allowances into it:
// abs_err = max(request.abs_err, tie) and the relative test switched off. The distance found
// is within abs_err of the minimum over triangle pairs; among pairs tied to within `tie` the
// first one found is kept. tie = 0 and no request allowance: fcl::distance itself.
#pragma once

#include <fcl/narrowphase/distance_request.h>
#include <fcl/narrowphase/distance_result.h>
#include <fcl/geometry/collision_geometry.h>

namespace bayesgrasp::sim {

/// Distance from `object` (identity pose) to `link` at T, as fcl::distance, with the allowance
/// above (pairs nearer each other than `tie` metres count as tied) when both are BVH meshes of
/// the same bounding volume (OBBRSS or RSS); any other pair goes to fcl::distance unchanged. `res` may carry a preset min_distance (a cap). With
/// `bv_tests`, the number of bounding-volume pairs the traversal tested is stored there (0 for a
/// pair that fcl::distance handled: not two BVHs of one kind).
void bvh_distance(const fcl::CollisionGeometryd* object, const fcl::CollisionGeometryd* link,
                  const fcl::Transform3d& T, const fcl::DistanceRequestd& req, fcl::DistanceResultd& res,
                  double tie, int* bv_tests = nullptr);

}  // namespace bayesgrasp::sim
