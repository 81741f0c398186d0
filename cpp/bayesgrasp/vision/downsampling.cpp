#include "bayesgrasp/vision/pcl_cloud.hpp"  // first: PCL_NO_PRECOMPILE

#include <pcl/filters/voxel_grid.h>

namespace bayesgrasp::vision {

namespace {
OrientedCloud finite_rows(const Points& P, const Points* N) {
  OrientedCloud c;
  c.points.reserve(P.rows());
  c.normals.reserve(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    if (!P.row(i).allFinite()) continue;
    c.points.push_back(P.row(i).transpose().cast<float>());
    c.normals.push_back(N ? Eigen::Vector3f(N->row(i).transpose().cast<float>()) : Eigen::Vector3f::Zero());
  }
  return c;
}
}  // namespace

OrientedCloud finite_points(const Points& P) { return finite_rows(P, nullptr); }
OrientedCloud finite_points(const SurfaceSamples& S) { return finite_rows(S.points, &S.normals); }

CloudN::Ptr to_pcl(const OrientedCloud& cloud) {
  CloudN::Ptr c(new CloudN);
  c->reserve(cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    pcl::PointNormal p;
    p.x = cloud.points[i].x();
    p.y = cloud.points[i].y();
    p.z = cloud.points[i].z();
    p.normal_x = cloud.normals[i].x();
    p.normal_y = cloud.normals[i].y();
    p.normal_z = cloud.normals[i].z();
    p.curvature = 0.f;
    c->push_back(p);
  }
  c->width = static_cast<std::uint32_t>(c->size());
  c->height = 1;
  c->is_dense = true;
  return c;
}

OrientedCloud voxel_downsample(const OrientedCloud& cloud, double voxel) {
  CloudN down;
  pcl::VoxelGrid<pcl::PointNormal> vg;
  vg.setInputCloud(to_pcl(cloud));
  const float leaf = static_cast<float>(voxel);
  vg.setLeafSize(leaf, leaf, leaf);
  vg.filter(down);  // averages xyz and the (reference) normals of each voxel
  OrientedCloud out;
  out.points.reserve(down.size());
  out.normals.reserve(down.size());
  for (const auto& p : down) {
    out.points.push_back(p.getVector3fMap());
    out.normals.emplace_back(p.normal_x, p.normal_y, p.normal_z);
  }
  return out;
}

std::vector<Eigen::Vector3d> to_double(const PointsF& points) {
  std::vector<Eigen::Vector3d> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = points[i].cast<double>();
  return out;
}

}  // namespace bayesgrasp::vision
