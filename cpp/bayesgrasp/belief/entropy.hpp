// Entropy estimates of a weighted particle set and the expected posterior entropy of an action
// (thesis Eq. 3.2, Publications III-IV).
#pragma once

#include "bayesgrasp/belief/particles.hpp"

namespace bayesgrasp::belief {

/// The thesis's weight-based estimate: -sum w_i log w_i of the normalised weights (0 log 0 = 0).
/// Uniform weights give log N. Throws on NaN, zero particles or all-zero weights.
double weight_entropy(const Eigen::VectorXd& log_weights);

enum class Bandwidth { Scott, Silverman };
Bandwidth bandwidth_from_string(const std::string& s);

/// Kernel-density estimate using the particle positions: a weighted Gaussian KDE with kernel
/// covariance f^2 * C, C the weighted sample covariance (unbiased, divided by 1 - sum w^2) and
/// f = n_eff^(-1/(D+4)) (Scott) or (n_eff (D+2)/4)^(-1/(D+4)) (Silverman), n_eff = 1/sum w^2 —
/// the conventions of scipy.stats.gaussian_kde. The entropy by resubstitution is
/// -sum_i w_i log p(x_i). For wrapping dims differences are wrapped (valid while the spread is
/// small against the period). A singular C (e.g. all particles equal) gets a relative ridge of
/// 1e-10 (or 1e-12 absolute). O(N^2 D).
double kde_entropy(const RowMatrixXd& particles, const Eigen::VectorXd& log_weights, const StateSpace& space,
                   Bandwidth bw = Bandwidth::Scott);

struct EntropyEstimate {
  double mean = 0.0;       ///< the expected posterior entropy
  double std_error = 0.0;  ///< standard error of the Monte-Carlo mean
};

/// Expected posterior (weight) entropy after taking an action (Eq. 3.2), by sampling measurements.
///   mean, var: (N, K) predictive mean and variance of the K measurement outputs at each particle
///              for this action (e.g. one GP prediction per particle); var > 0 (include the noise).
/// For each of n_samples: draw a particle j with probability w_j (stratified over the samples),
/// draw m ~ N(mean_j, diag var_j), reweight every particle by N(m; mean_i, diag var_i), take the
/// weight entropy; return the average. The same seed gives the same draws (for every action: common
/// random numbers, so differences between actions are not swamped by sampling noise).
EntropyEstimate expected_posterior_entropy(const Eigen::VectorXd& log_weights, const RowMatrixXd& mean,
                                           const RowMatrixXd& var, int n_samples, std::uint64_t seed);

/// The same for A candidate actions at once: mean and var are (A*N, K), rows a*N .. a*N+N-1 for
/// action a. Actions are independent (n_threads OpenMP threads; 0 = all cores, negative throws).
std::vector<EntropyEstimate> expected_posterior_entropy_batch(const Eigen::VectorXd& log_weights,
                                                              const RowMatrixXd& mean, const RowMatrixXd& var,
                                                              int n_actions, int n_samples, std::uint64_t seed,
                                                              int n_threads = 1);

}  // namespace bayesgrasp::belief
