// Normals and FPFH descriptors of a downsampled cloud: ours (features_own.cpp) and PCL's
// (features_pcl.cpp), with the same definitions and the same normal orientation (orient() below).
#pragma once

#include <Eigen/Core>

#include "bayesgrasp/vision/oriented_cloud.hpp"
#include "bayesgrasp/vision/registration_options.hpp"

namespace bayesgrasp::vision {

/// FPFH: 3 x 11 bins, one row per point.
using Features = Eigen::Matrix<float, Eigen::Dynamic, 33, Eigen::RowMajor>;

/// How an estimated normal, defined up to sign, is oriented.
struct NormalOrientation {
  enum class Rule {
    TowardsViewpoint,  // a scene seen from a known camera centre
    AlongReference,    // a model: along the reference normals carried by its points
    AwayFromCentroid,  // a scene without a viewpoint
  };
  Rule rule = Rule::AwayFromCentroid;
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();

  static NormalOrientation towards(const Eigen::Vector3d& viewpoint) {
    return {Rule::TowardsViewpoint, viewpoint.cast<float>()};
  }
  static NormalOrientation along_reference() { return {Rule::AlongReference, Eigen::Vector3f::Zero()}; }
  static NormalOrientation away_from_centroid() { return {Rule::AwayFromCentroid, Eigen::Vector3f::Zero()}; }
};

/// n or -n, as `orientation` says, for a normal n at point p with reference normal `reference`;
/// `centroid` is the cloud's (AwayFromCentroid).
inline Eigen::Vector3f orient(const NormalOrientation& orientation, const Eigen::Vector3f& n, const Eigen::Vector3f& p,
                              const Eigen::Vector3f& reference, const Eigen::Vector3f& centroid) {
  using Rule = NormalOrientation::Rule;
  float along = 0.f;
  switch (orientation.rule) {
    case Rule::AlongReference: along = n.dot(reference); break;
    case Rule::AwayFromCentroid: along = n.dot(p - centroid); break;
    case Rule::TowardsViewpoint: along = n.dot(orientation.viewpoint - p); break;
  }
  return along < 0 ? Eigen::Vector3f(-n) : n;
}

/// Mean of the points (single precision, summed in order); zero for no points.
Eigen::Vector3f centroid(const PointsF& points);

/// A cloud prepared for matching: the points that have a normal, their oriented normals and FPFH.
struct FeatureCloud {
  OrientedCloud cloud;
  Features features;  // one row per point of cloud
};

/// Normals by PCA over normal_radius (m), oriented, then FPFH over feature_radius (m), by the
/// estimator the options name. `threads`: OpenMP threads inside the estimator.
FeatureCloud estimate_features(const OrientedCloud& down, const FeatureOptions& options, double voxel,
                               const NormalOrientation& orientation, int threads);

/// Ours: neighbours from one fixed-radius grid search per point, shared by normals and FPFH.
FeatureCloud own_features(const OrientedCloud& down, double normal_radius, double feature_radius,
                          const NormalOrientation& orientation, int threads);

/// PCL's NormalEstimationOMP and FPFHEstimationOMP.
FeatureCloud pcl_features(const OrientedCloud& down, double normal_radius, double feature_radius,
                          const NormalOrientation& orientation, int threads);

}  // namespace bayesgrasp::vision
