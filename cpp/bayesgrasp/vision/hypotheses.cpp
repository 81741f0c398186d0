#include "bayesgrasp/vision/hypotheses.hpp"

#include <algorithm>
#include <limits>

#include "bayesgrasp/vision/icp.hpp"

namespace bayesgrasp::vision {

std::vector<Eigen::Vector3d> subsample(const std::vector<Eigen::Vector3d>& points, int count) {
  const int n = static_cast<int>(points.size());
  std::vector<Eigen::Vector3d> sub;
  const int stride = std::max(1, n / count);
  for (int i = 0; i < n; i += stride) sub.push_back(points[i]);
  return sub;
}

std::vector<Hypothesis> rank_hypotheses(std::vector<Hypothesis> hypotheses, const DenseModel& model,
                                        const std::vector<Eigen::Vector3d>& sub, const StepContext& c) {
  std::stable_sort(hypotheses.begin(), hypotheses.end(),
                   [](const Hypothesis& a, const Hypothesis& b) { return a.inliers > b.inliers; });
  std::vector<Hypothesis> distinct;
  for (const auto& h : hypotheses) {
    bool dup = false;
    for (const auto& g : distinct) dup = dup || same_hypothesis(g.T, h.T, c.voxel);
    if (!dup) distinct.push_back(h);
  }
  for (auto& h : distinct) h.cost = measure_fit(model, sub, h.T, c.tau).delta;
  std::stable_sort(distinct.begin(), distinct.end(),
                   [](const Hypothesis& a, const Hypothesis& b) { return a.cost < b.cost; });
  const int keep = c.options.ransac.hypotheses;
  if (static_cast<int>(distinct.size()) > keep) distinct.resize(keep);
  return distinct;
}

Iso3 choose_hypothesis(const std::vector<Hypothesis>& ranked, const DenseModel& model,
                       const std::vector<Eigen::Vector3d>& sub, const StepContext& c) {
  const IcpOptions& icp = c.options.icp;
  double best_cost = std::numeric_limits<double>::infinity();
  Iso3 best_T = Iso3::Identity();
  for (const auto& h : ranked) {
    const Iso3 T = point_to_plane_icp(model, sub, h.T, icp.distance * c.voxel, icp.coarse_iterations, icp.tolerance);
    const double cost = selection_cost(measure_fit(model, sub, T, c.tau), T, c.tau, c.up, c.options.up_prior);
    if (cost < best_cost) {
      best_cost = cost;
      best_T = T;
    }
  }
  return best_T;
}

}  // namespace bayesgrasp::vision
