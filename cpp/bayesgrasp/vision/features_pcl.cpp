// PCL's normal and FPFH estimators, the reference for ours (features_own.cpp).
#include "bayesgrasp/vision/pcl_cloud.hpp"  // first: PCL_NO_PRECOMPILE

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>

#include "bayesgrasp/vision/features.hpp"

namespace bayesgrasp::vision {

namespace {
// PCL's normals, oriented by orient() (PCL itself flips them towards the viewpoint it is given);
// the points without a finite normal are left out.
OrientedCloud pcl_normals(const OrientedCloud& down, double normal_radius, const NormalOrientation& orientation,
                          int threads) {
  const CloudN::Ptr in = to_pcl(down);
  pcl::NormalEstimationOMP<pcl::PointNormal, pcl::PointNormal> ne(threads);
  ne.setInputCloud(in);
  ne.setRadiusSearch(normal_radius);
  ne.setViewPoint(orientation.viewpoint.x(), orientation.viewpoint.y(), orientation.viewpoint.z());
  CloudN est;
  ne.compute(est);
  const Eigen::Vector3f c = centroid(down.points);
  OrientedCloud out;
  for (int i = 0; i < down.size(); ++i) {
    const Eigen::Vector3f n(est[i].normal_x, est[i].normal_y, est[i].normal_z);
    if (!n.allFinite() || n.norm() < 0.5f) continue;
    out.points.push_back(down.points[i]);
    out.normals.push_back(orient(orientation, n, down.points[i], down.normals[i], c));
  }
  return out;
}
}  // namespace

FeatureCloud pcl_features(const OrientedCloud& down, double normal_radius, double feature_radius,
                          const NormalOrientation& orientation, int threads) {
  FeatureCloud out;
  out.cloud = pcl_normals(down, normal_radius, orientation, threads);
  if (out.cloud.size() == 0) return out;
  const CloudN::Ptr withn = to_pcl(out.cloud);
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fe(threads);
  fe.setInputCloud(withn);
  fe.setInputNormals(withn);
  fe.setRadiusSearch(feature_radius);
  pcl::PointCloud<pcl::FPFHSignature33> f;
  fe.compute(f);
  out.features.resize(static_cast<Eigen::Index>(f.size()), 33);
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int j = 0; j < 33; ++j) out.features(static_cast<Eigen::Index>(i), j) = f[i].histogram[j];
  return out;
}

}  // namespace bayesgrasp::vision
