// All PCL templates are instantiated here, in our own flags, instead of using the instances
// precompiled into Debian's libpcl_*.so: with -march=native Eigen's heap alignment (and so its
// aligned_malloc/free) differs from the library's SSE2 build, and memory allocated on one side and
// freed on the other (e.g. point-cloud storage resized inside a filter) would corrupt the heap.
#define PCL_NO_PRECOMPILE
#include "bayesgrasp/vision/segmentation.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bayesgrasp/common/checks.hpp"

namespace bayesgrasp::vision {

void validate(const SegmentationOptions& P) {
  require_positive(P.plane_threshold, "plane_threshold");
  require_at_least(P.plane_iterations, 1, "plane_iterations");
  require_finite(P.min_height, "min_height");
  require_finite(P.max_height, "max_height");
  if (!(P.max_height > P.min_height)) bad_field("max_height", "above min_height", number_str(P.max_height));
  require_positive(P.cluster_tolerance, "cluster_tolerance");
  require_at_least(P.min_cluster_size, 1, "min_cluster_size");
  require_at_least(P.max_cluster_size, P.min_cluster_size, "max_cluster_size");
  if (!P.up.allFinite() || !(P.up.norm() > 0)) throw std::invalid_argument("up: must be finite and non-zero");
}

SegmentationResult segment_table(const Points& cloud, const SegmentationOptions& P) {
  validate(P);
  pcl::PointCloud<pcl::PointXYZ>::Ptr c(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<int> rows;  // cloud row of each finite point
  c->reserve(cloud.rows());
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) {
    if (!cloud.row(i).allFinite()) continue;
    c->push_back(pcl::PointXYZ(static_cast<float>(cloud(i, 0)), static_cast<float>(cloud(i, 1)),
                               static_cast<float>(cloud(i, 2))));
    rows.push_back(static_cast<int>(i));
  }
  c->width = static_cast<std::uint32_t>(c->size());
  c->height = 1;
  if (c->size() < 3) throw std::invalid_argument("cloud: has fewer than 3 finite points");

  // The plane by RANSAC on the plane model alone (pcl::SACSegmentation would instantiate every
  // sample-consensus model under PCL_NO_PRECOMPILE: the longest compile of the build). The same
  // steps as SACSegmentation::segment with SACMODEL_PLANE, SAC_RANSAC and optimised coefficients:
  // RANSAC (probability 0.99, fixed sampling seed), a least-squares refit on its inliers, the
  // inliers re-selected within the threshold of the refitted plane.
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(c, /*random=*/false));
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, P.plane_threshold);
  ransac.setProbability(0.99);
  ransac.setMaxIterations(P.plane_iterations);
  pcl::Indices inliers;
  Eigen::VectorXf coarse(4), refined(4);
  if (ransac.computeModel(0)) {
    ransac.getInliers(inliers);
    ransac.getModelCoefficients(coarse);
    model->optimizeModelCoefficients(inliers, coarse, refined);
    model->selectWithinDistance(refined, P.plane_threshold, inliers);
  }
  if (inliers.empty()) throw std::invalid_argument("cloud: no plane found");

  SegmentationResult out;
  Eigen::Vector4d pl = refined.cast<double>();
  pl /= pl.head<3>().norm();
  if (pl.head<3>().dot(P.up) < 0) pl = -pl;
  out.plane = pl;
  for (auto i : inliers) out.plane_inliers.push_back(rows[i]);

  pcl::PointCloud<pcl::PointXYZ>::Ptr above(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<int> above_rows;
  for (std::size_t i = 0; i < c->size(); ++i) {
    const auto& p = (*c)[i];
    const double h = pl.head<3>().dot(Vec3(p.x, p.y, p.z)) + pl(3);
    if (h >= P.min_height && h <= P.max_height) {
      above->push_back(p);
      above_rows.push_back(rows[i]);
    }
  }
  above->width = static_cast<std::uint32_t>(above->size());
  above->height = 1;
  if (above->empty()) return out;

  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(above);
  std::vector<pcl::PointIndices> clusters;
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(P.cluster_tolerance);
  ec.setMinClusterSize(P.min_cluster_size);
  ec.setMaxClusterSize(P.max_cluster_size);
  ec.setSearchMethod(tree);
  ec.setInputCloud(above);
  ec.extract(clusters);
  // Largest first; ties by smallest first row, so the order is deterministic.
  std::vector<std::vector<int>> cl;
  for (const auto& ci : clusters) {
    std::vector<int> r;
    r.reserve(ci.indices.size());
    for (auto i : ci.indices) r.push_back(above_rows[i]);
    std::sort(r.begin(), r.end());
    cl.push_back(std::move(r));
  }
  std::sort(cl.begin(), cl.end(), [](const std::vector<int>& a, const std::vector<int>& b) {
    return a.size() != b.size() ? a.size() > b.size() : a.front() < b.front();
  });
  for (auto& r : cl) {
    Points pts(static_cast<Eigen::Index>(r.size()), 3);
    for (std::size_t j = 0; j < r.size(); ++j) pts.row(static_cast<Eigen::Index>(j)) = cloud.row(r[j]);
    out.cluster_points.push_back(std::move(pts));
    out.clusters.push_back(std::move(r));
  }
  return out;
}

}  // namespace bayesgrasp::vision
