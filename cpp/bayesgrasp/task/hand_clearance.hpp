// The environment constraint of the category planner: the open hand at a candidate pose must be
// clear of the table and of the observed cloud before it approaches. For each candidate hand pose
// the deepest intrusion (m, >= 0; 0 = clear) of the table plane z = 0 and of any cloud point into
// the hand's collision shapes (capsules and boxes of HandModel, grown by `margin`), batched.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp::task {

using CloudPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct ClearanceOptions {
  bool table = true;     // the table plane z = 0 is an obstacle
  double margin = 0.0;   // shapes grown by this (m) for the check, >= 0
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const ClearanceOptions& options);

struct Clearance {
  Eigen::VectorXd table;  // N: how deep the hand reaches below z = 0 (m), 0 if above
  Eigen::VectorXd cloud;  // N: the deepest cloud point inside a hand shape (m), 0 if none
};

/// Intrusions of the table and the cloud into the hand (joints `q`, HandModel layout) at each
/// pose. Throws std::invalid_argument for bad joints, non-finite poses or points, a negative
/// margin. threads: 0 = all cores.
Clearance hand_clearance(const HandModel& hand, const Eigen::VectorXd& q, const std::vector<Iso3>& poses,
                         const CloudPoints& cloud, const ClearanceOptions& options = {}, int threads = 1);

/// Depth of point p inside a shape (in the shape's link frame) grown by margin: > 0 inside.
double shape_depth(const Shape& s, const Vec3& p_link, double margin);

}  // namespace bayesgrasp::task
