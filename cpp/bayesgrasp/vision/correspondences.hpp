// Feature correspondences between a scene and a model (brute force, L2 between descriptors).
#pragma once

#include <utility>
#include <vector>

#include "bayesgrasp/vision/features.hpp"

namespace bayesgrasp::vision {

/// Descriptors as compared: square roots of the histograms for the Hellinger distance (or the
/// histograms), with their squared norms.
struct MatchDescriptors {
  Features f;
  Eigen::VectorXf sq_norm;
  int size() const { return static_cast<int>(f.rows()); }
};

MatchDescriptors match_descriptors(const Features& features, bool hellinger);

/// (scene point, model point) pairs.
using Correspondences = std::vector<std::pair<int, int>>;

/// Each scene descriptor's k nearest model descriptors (ties: the lower index first), and with
/// options.reverse each model descriptor's nearest scene descriptor, which keeps the matches
/// spread over the model when many scene descriptors share a few nearest model descriptors
/// ("hubs", e.g. on flat faces).
Correspondences correspondences(const MatchDescriptors& scene, const MatchDescriptors& model,
                                const CorrespondenceOptions& options);

}  // namespace bayesgrasp::vision
