// Weighted particle beliefs over a box-bounded state (the planar object pose x, y, yaw is the
// main case; dimensions flagged "wraps" are angles kept in [low, high)).
//
// Weights are stored as log-weights. Updates: reweighting by log-likelihoods (with a defined
// recovery when every likelihood is zero), resampling (systematic, stratified, multinomial),
// Metropolis random-walk moves under a batch log-target and roughening (Gordon et al. 1993).
// All randomness comes from a seeded generator passed in.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::belief {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using bayesgrasp::Rng;        // common/random.hpp: the seeded engine and its uniform [0, 1)
using bayesgrasp::uniform01;

/// Batch log-likelihood (or log-target): X is (N, D); writes ll (already sized N).
/// -inf is allowed (zero likelihood); NaN and +inf are errors.
using BatchLogLikelihood = std::function<void(const RowMatrixXd& X, Eigen::VectorXd& ll)>;

/// The state's box and which dimensions wrap (angles: wrapped into [low, high)).
struct StateSpace {
  Eigen::VectorXd low, high;
  std::vector<bool> wraps;  ///< empty: none wraps

  StateSpace() = default;
  StateSpace(Eigen::VectorXd lo, Eigen::VectorXd hi, std::vector<bool> w = {});
  /// x, y, yaw with yaw wrapping in [-pi, pi).
  static StateSpace planar_pose(double x_low, double x_high, double y_low, double y_high);

  int dim() const { return static_cast<int>(low.size()); }
  bool wrap(int k) const { return !wraps.empty() && wraps[k]; }
  /// Throws std::invalid_argument (low > high, non-finite, size mismatch, zero-width wrapping dim).
  void validate() const;
  /// Maps a wrapping coordinate into [low, high).
  double wrap_value(int k, double v) const;
  /// Signed difference a - b, wrapped into [-period/2, period/2) for wrapping dims.
  double difference(int k, double a, double b) const;
  /// True if x is inside the box in every non-wrapping dimension.
  bool contains(const double* x) const;
  /// Wraps the wrapping dims and checks the rest are inside the box; throws naming `what`.
  void canonicalise(RowMatrixXd& X, const char* what) const;
};

enum class Resampling { Systematic, Stratified, Multinomial };
/// "systematic", "stratified" or "multinomial".
Resampling resampling_from_string(const std::string& s);

/// Normalised weights from log-weights (log-sum-exp). Throws if any is NaN/+inf or all are -inf.
Eigen::VectorXd normalised_weights(const Eigen::VectorXd& log_weights);
/// log sum exp(v); -inf if all are -inf.
double log_sum_exp(const Eigen::VectorXd& v);

/// Indices of n particles drawn with probabilities w (w normalised, non-negative).
/// Systematic: one uniform offset; stratified: one uniform per stratum; multinomial: iid.
/// All three give expected copy counts n * w_i.
std::vector<int> resample_indices(const Eigen::VectorXd& w, int n, Resampling scheme, Rng& rng);

struct MetropolisStats {
  double acceptance_rate = 0.0;
  long long evaluations = 0;
};

class ParticleBelief {
 public:
  /// particles (N, D) must lie in the box (wrapping dims are wrapped); log_weights empty = uniform.
  ParticleBelief(StateSpace space, RowMatrixXd particles, Eigen::VectorXd log_weights = {});

  /// N particles uniform in the box.
  static ParticleBelief uniform(const StateSpace& space, int n, Rng& rng);
  /// N particles from N(mean, diag(std^2)); draws outside the box (non-wrapping dims) are
  /// redrawn (truncated Gaussian; at most 1000 tries, then clipped).
  static ParticleBelief gaussian(const StateSpace& space, const Eigen::VectorXd& mean,
                                 const Eigen::VectorXd& std, int n, Rng& rng);

  const StateSpace& space() const { return space_; }
  const RowMatrixXd& particles() const { return X_; }
  const Eigen::VectorXd& log_weights() const { return lw_; }
  int size() const { return static_cast<int>(X_.rows()); }
  int dim() const { return static_cast<int>(X_.cols()); }

  /// Normalised weights (sum 1).
  Eigen::VectorXd weights() const { return normalised_weights(lw_); }
  /// Shifts the log-weights so that they log-sum-exp to 0.
  void normalise();
  /// Effective sample size 1 / sum w_i^2 (normalised weights), in [1, N].
  double ess() const;
  /// Weighted mean (circular mean for wrapping dims).
  Eigen::VectorXd mean() const;

  /// Adds log-likelihoods to the log-weights and normalises. If every likelihood is zero
  /// (all -inf after adding) the weights are reset to uniform and true is returned (the caller
  /// warns); NaN or +inf throws. Returns false otherwise.
  bool reweight(const Eigen::VectorXd& log_likelihood);
  /// Evaluates the likelihood at the particles in one batch call, then reweight().
  bool update(const BatchLogLikelihood& log_likelihood);

  /// Draws N particles (or n if n > 0) by the scheme; the weights become uniform.
  void resample(Rng& rng, Resampling scheme = Resampling::Systematic, int n = 0);
  /// Resamples only when ess < threshold * N; returns whether it did.
  bool resample_if_needed(Rng& rng, double threshold = 0.5, Resampling scheme = Resampling::Systematic);

  /// Metropolis random walk: n_steps sweeps, each proposing x' = x + step .* N(0, I) for every
  /// particle and evaluating all proposals in one batch call of log_target. Proposals outside the
  /// box are rejected (the target is zero there); wrapping dims wrap. Weights are unchanged (the
  /// moves leave the target invariant). One extra batch call evaluates the current particles.
  MetropolisStats metropolis(const BatchLogLikelihood& log_target, const Eigen::VectorXd& step,
                             int n_steps, Rng& rng);

  /// Roughening (Gordon, Salmond & Smith 1993): adds N(0, sigma_k^2) jitter with
  /// sigma_k = k * E_k * N^(-1/D), E_k the particles' spread (max - min; the shortest arc
  /// covering them for wrapping dims). Non-wrapping dims are reflected into the box.
  void roughen(Rng& rng, double k = 0.2);

 private:
  StateSpace space_;
  RowMatrixXd X_;
  Eigen::VectorXd lw_;
};

}  // namespace bayesgrasp::belief
