// Planar poses (x, y, yaw) of grasps relative to object poses, and back. The relative pose is
// the GP input of the planners' measurement and stability models, built for every (action,
// particle) pair in one call; its inverse places grasps planned in an object's frame in the
// world. One implementation of both, used by the batch functions here and by the pose grid.
#pragma once

#include <cmath>
#include <vector>

#include "bayesgrasp/belief/particles.hpp"

namespace bayesgrasp::belief {

/// a wrapped into [-pi, pi).
inline double wrap_angle(double a) {
  double y = std::fmod(a + M_PI, 2.0 * M_PI);
  if (y < 0.0) y += 2.0 * M_PI;
  return y - M_PI;
}

/// An object's planar pose o = (x, y, yaw) with its rotation R(yaw) precomputed.
struct PlanarFrame {
  double x = 0.0, y = 0.0, yaw = 0.0;
  double c = 1.0, s = 0.0;  ///< cos(yaw), sin(yaw)

  PlanarFrame() = default;
  PlanarFrame(double px, double py, double pyaw) : x(px), y(py), yaw(pyaw), c(std::cos(pyaw)), s(std::sin(pyaw)) {}

  /// A world point p in this frame: R(-yaw) (p - o).
  void to_local(double px, double py, double& lx, double& ly) const {
    const double dx = px - x, dy = py - y;
    lx = c * dx + s * dy;
    ly = -s * dx + c * dy;
  }
  /// A point l of this frame in the world: o + R(yaw) l.
  void to_world(double lx, double ly, double& px, double& py) const {
    px = x + c * lx - s * ly;
    py = y + s * lx + c * ly;
  }
};

/// Throws std::invalid_argument naming `name` unless m has 3 columns (x, y, yaw), all finite.
void check_planar_poses(const RowMatrixXd& m, const char* name);

/// One frame per row (x, y, yaw) of poses (N, 3).
std::vector<PlanarFrame> planar_frames(const RowMatrixXd& poses);

/// Grasps relative to object poses, all pairs. actions: (A, 3 + E) rows (ax, ay, ayaw, extra...);
/// poses: (N, 3) rows (ox, oy, oyaw). Returns (A*N, 3 + E): row a*N + j =
/// (R(-oyaw_j) (a_xy - o_xy), wrap(ayaw - oyaw_j), extra_a...), the yaw wrapped into [-pi, pi).
RowMatrixXd relative_planar_pose(const RowMatrixXd& actions, const RowMatrixXd& poses);

/// The inverse: grasps given in object frames placed in the world, all pairs. relative:
/// (R, 3 + E) rows (rx, ry, ryaw, extra...); poses: (N, 3). Returns (R*N, 3 + E): row r*N + j =
/// (o_xy_j + R(oyaw_j) r_xy, wrap(ryaw + oyaw_j), extra_r...), the yaw wrapped into [-pi, pi).
/// compose_planar_pose(relative_planar_pose(a, o), o) = a (yaw wrapped) for a single pose o.
RowMatrixXd compose_planar_pose(const RowMatrixXd& relative, const RowMatrixXd& poses);

/// compose_planar_pose one to one: relative (N, 3 + E) and poses (N, 3) -> (N, 3 + E), row i =
/// relative_i placed by pose_i.
RowMatrixXd compose_planar_pose_paired(const RowMatrixXd& relative, const RowMatrixXd& poses);

}  // namespace bayesgrasp::belief
