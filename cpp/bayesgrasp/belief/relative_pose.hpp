// The planar relative pose of a grasp in an object's frame: the GP input of the planners'
// measurement and stability models, built for every (action, particle) pair in one call.
#pragma once

#include "bayesgrasp/belief/particles.hpp"

namespace bayesgrasp::belief {

/// actions: (A, 3 + P) rows (ax, ay, ayaw, extra...); poses: (N, 3) rows (ox, oy, oyaw).
/// Returns (A*N, 3 + P): row a*N + j = (R(-oyaw_j) (a_xy - o_xy), wrap(ayaw - oyaw_j), extra_a...),
/// the yaw wrapped into [-pi, pi).
RowMatrixXd relative_planar_pose(const RowMatrixXd& actions, const RowMatrixXd& poses);

}  // namespace bayesgrasp::belief
