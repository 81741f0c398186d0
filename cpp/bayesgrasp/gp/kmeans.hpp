// k-means++ for the inducing inputs of the sparse GP (Arthur & Vassilvitskii 2007).
#pragma once

#include <Eigen/Core>

#include <cstdint>

namespace bayesgrasp::gp {

/// k-means++ seeding (seeded std::mt19937_64) followed by `iters` Lloyd iterations; returns up
/// to k centres (k, D) (fewer if X has fewer distinct rows). Empty clusters keep their centre.
Eigen::MatrixXd kmeans_pp(const Eigen::MatrixXd& X, int k, std::uint64_t seed, int iters = 10);

}  // namespace bayesgrasp::gp
