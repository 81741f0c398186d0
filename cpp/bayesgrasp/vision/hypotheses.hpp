// From RANSAC's hypotheses to one transform: the distinct ones ranked by fitting error on a scene
// subsample, the best few refined by a coarse ICP, the winner chosen by fitting error plus the up
// prior's upside-down penalty.
#pragma once

#include <vector>

#include "bayesgrasp/vision/ransac.hpp"
#include "bayesgrasp/vision/fit.hpp"

namespace bayesgrasp::vision {

/// Every stride-th scene point, stride = max(1, n / count).
std::vector<Eigen::Vector3d> subsample(const std::vector<Eigen::Vector3d>& points, int count);

/// The hypotheses by consensus (stable), duplicates (same_hypothesis) dropped, ranked by delta on
/// `sub` (cost), the best options.ransac.hypotheses kept.
std::vector<Hypothesis> rank_hypotheses(std::vector<Hypothesis> hypotheses, const DenseModel& model,
                                        const std::vector<Eigen::Vector3d>& sub, const StepContext& context);

/// Each hypothesis refined by a coarse ICP on `sub`; the one of least selection_cost (the first
/// of equal costs). `ranked` must not be empty.
Iso3 choose_hypothesis(const std::vector<Hypothesis>& ranked, const DenseModel& model,
                       const std::vector<Eigen::Vector3d>& sub, const StepContext& context);

}  // namespace bayesgrasp::vision
