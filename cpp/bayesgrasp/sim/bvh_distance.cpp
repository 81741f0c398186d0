#include "bayesgrasp/sim/bvh_distance.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/RSS.h>
#include <fcl/narrowphase/detail/traversal/distance/mesh_distance_traversal_node.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <limits>

namespace bayesgrasp::sim {

namespace {

/// One oriented mesh-mesh traversal (OBBRSS or RSS nodes), set up as FCL's own
/// orientedMeshDistance does, with the allowances written into the node.
template <class Node, class BV>
void oriented_distance(const fcl::BVHModel<BV>& a, const fcl::BVHModel<BV>& b, const fcl::Transform3d& T,
                       const fcl::DistanceRequestd& req, fcl::DistanceResultd& res, double tie, int* bv_tests) {
  if (bv_tests) *bv_tests = 0;
  if (req.isSatisfied(res)) return;
  Node node;
  fcl::detail::initialize(node, a, fcl::Transform3d::Identity(), b, T, req, res);
  node.abs_err = std::max(req.abs_err, tie);
  // With an allowance the relative test always passes (c > 0); without, FCL's own test.
  node.rel_err = node.abs_err > 0.0 ? std::numeric_limits<double>::max() / 4 : 0.0;
  node.enable_statistics = bv_tests != nullptr;
  fcl::detail::distance(&node);
  if (bv_tests) *bv_tests = node.num_bv_tests;
}

}  // namespace

void bvh_distance(const fcl::CollisionGeometryd* object, const fcl::CollisionGeometryd* link,
                  const fcl::Transform3d& T, const fcl::DistanceRequestd& req, fcl::DistanceResultd& res,
                  double tie, int* bv_tests) {
  const bool own = tie > 0.0 || req.abs_err > 0.0 || bv_tests;  // else fcl::distance is the same
  if (own && object->getNodeType() == fcl::BV_OBBRSS && link->getNodeType() == fcl::BV_OBBRSS) {
    using M = fcl::BVHModel<fcl::OBBRSSd>;
    oriented_distance<fcl::detail::MeshDistanceTraversalNodeOBBRSS<double>>(
        *static_cast<const M*>(object), *static_cast<const M*>(link), T, req, res, tie, bv_tests);
  } else if (own && object->getNodeType() == fcl::BV_RSS && link->getNodeType() == fcl::BV_RSS) {
    using M = fcl::BVHModel<fcl::RSSd>;
    oriented_distance<fcl::detail::MeshDistanceTraversalNodeRSS<double>>(
        *static_cast<const M*>(object), *static_cast<const M*>(link), T, req, res, tie, bv_tests);
  } else {
    if (bv_tests) *bv_tests = 0;
    fcl::distance(object, fcl::Transform3d::Identity(), link, T, req, res);
  }
}

}  // namespace bayesgrasp::sim
