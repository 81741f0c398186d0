// A tabulated model over planar relative grasp poses (x, y, yaw): a regular grid of C channels
// (e.g. the stability probability and the measurement GP's mean and variance per joint) with
// trilinear interpolation, yaw periodic. The planners query their models at every
// (candidate grasp, particle) pair - hundreds of thousands of points per decision - and a GP
// prediction with variance costs O(M^2) per point; the table costs eight lookups. It is built
// once per model from the GP itself, so it approximates the GP, not the simulator.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "bayesgrasp/belief/entropy.hpp"
#include "bayesgrasp/belief/particles.hpp"

namespace bayesgrasp::belief {

class RelativePoseGrid {
 public:
  /// Nodes: x_i = lo[0] + i (hi[0] - lo[0]) / (nx - 1) (i < nx), likewise y, and
  /// yaw_k = -pi + 2 pi k / nyaw (periodic). values: (nx * ny * nyaw, C), row (ix * ny + iy) * nyaw + k.
  /// outside: (C,) values returned where x or y lies outside [lo, hi] per channel, or NaN to use
  /// the nearest edge value (clamping). Throws std::invalid_argument on bad sizes or values.
  RelativePoseGrid(std::array<double, 2> lo, std::array<double, 2> hi, int nx, int ny, int nyaw,
                   RowMatrixXd values, Eigen::VectorXd outside);

  int channels() const { return static_cast<int>(values_.cols()); }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nyaw() const { return nyaw_; }

  /// Values at relative poses rel (P, 3) -> (P, C).
  RowMatrixXd interpolate(const RowMatrixXd& rel) const;

  /// Values at the pose of each action (A, 3) relative to each object pose (N, 3), channels
  /// [c0, c0 + nc): (A * N, nc), row a * N + j (the layout of relative_planar_pose). n_threads:
  /// OpenMP threads over the actions (0 = all cores).
  RowMatrixXd interpolate_pairs(const RowMatrixXd& actions, const RowMatrixXd& poses, int c0, int nc,
                                int n_threads = 1) const;

  /// sum_j w_j value_c(action_a relative to pose_j) for every action: (A,). weights (N,) >= 0.
  Eigen::VectorXd expected(const RowMatrixXd& actions, const RowMatrixXd& poses, const Eigen::VectorXd& weights,
                           int channel, int n_threads = 1) const;

  /// Expected posterior weight entropy (Eq. 3.2) of every action, the measurement's mean in
  /// channels [mean_c0, mean_c0 + K) and its variance (with noise) in [var_c0, var_c0 + K).
  std::vector<EntropyEstimate> expected_posterior_entropy(const RowMatrixXd& actions, const RowMatrixXd& poses,
                                                          const Eigen::VectorXd& log_weights, int mean_c0,
                                                          int var_c0, int k, int n_samples, std::uint64_t seed,
                                                          int n_threads = 1) const;

 private:
  void at(double x, double y, double yaw, int c0, int nc, double* out) const;

  std::array<double, 2> lo_, hi_;
  int nx_, ny_, nyaw_;
  double sx_, sy_, syaw_;  // nodes per unit
  RowMatrixXd values_;
  // The same values channel by channel (column-major): a one-channel lookup (the stability
  // field of Eq. 3.1, the planners' innermost loop) then reads one small contiguous array
  // instead of strided rows of the whole table, which does not fit in cache; single precision
  // halves that array again (relative rounding 2^-24, far below the table's interpolation error).
  Eigen::MatrixXf channel_major_;
  Eigen::VectorXd outside_;
};

}  // namespace bayesgrasp::belief
