// The options of a registration with the quantities derived from them that several steps use.
#pragma once

#include "bayesgrasp/vision/registration_options.hpp"

namespace bayesgrasp::vision {

struct StepContext {
  const RegistrationOptions& options;
  Eigen::Vector3d up;  // the up prior's axis, unit, scene frame (+z if none is given)
  double voxel;        // m
  double tau;          // inlier distance, m

  explicit StepContext(const RegistrationOptions& o)
      : options(o),
        up(o.up_prior.up.norm() > 0 ? Eigen::Vector3d(o.up_prior.up.normalized()) : Eigen::Vector3d::UnitZ()),
        voxel(o.voxel),
        tau(o.inlier_distance * o.voxel) {}
};

}  // namespace bayesgrasp::vision
