// Non-rigid point set registration by Coherent Point Drift (Myronenko & Song, "Point Set
// Registration: Coherent Point Drift", IEEE TPAMI 32(12), 2010, Sec. 5 and Fig. 4).
//
// The model's points Y (M x 3) are the centroids of a Gaussian mixture that moves by a smooth
// displacement field v onto the observed points X (N x 3), with a uniform outlier component of
// weight w. v lies in the RKHS of the Gaussian kernel G(a, b) = exp(-|a - b|^2 / (2 beta^2)),
// regularised by lambda/2 |v|^2 (motion coherence): the points the camera does not see move with
// their neighbours. EM, with T = Y + G W the moved model:
//   E-step  P_mn = exp(-|x_n - t_m|^2 / 2 s2) / (sum_k exp(-|x_n - t_k|^2 / 2 s2) + c),
//           c = (2 pi s2)^(3/2) w / (1 - w) M / N
//   M-step  (G + lambda s2 d(P1)^-1) W = d(P1)^-1 P X - Y
//           s2 = (tr(X^T d(P^T 1) X) - 2 tr((P X)^T T) + tr(T^T d(P1) T)) / (3 N_P),  N_P = 1^T P 1
// Low rank (the paper's Sec. 5.1 uses the top eigenvectors of G; we use the Nystrom form, which
// needs no eigensolver): G ~ C L^-1 C^T with C = G(Y, landmarks), L = G(landmarks, landmarks),
// the K landmarks chosen by farthest-point sampling (deterministic). The M-step is then solved by
// the Woodbury identity in K x K, and the field is v(z) = sum_k G(z, l_k) a_k with a = L^-1 C^T W,
// defined everywhere (the mesh's vertices, its labels' triangles, its grasps). K = M is exact.
//
// Units: both sets are normalised by the model's centroid and RMS radius (one transform for
// both, so the rigid registration's alignment is kept; a partial view's centroid is not the
// object's); beta is in RMS radii; results are in the input units.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace bayesgrasp::deform {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct CpdOptions {
  double beta = 2.0;          // kernel width, in the model's RMS radii (larger: stiffer, smoother field)
  double lam = 2.0;           // lambda: regularisation weight of the field's RKHS norm (larger: smaller motion)
  double outlier_weight = 0.1;  // w in [0, 1): the uniform component's share (clutter, noise)
  int max_iterations = 100;
  double tolerance = 1e-3;    // stop when the variance changes by less than this fraction (1e-5: same fit, 2-3x the iterations)
  int rank = 120;             // Nystrom landmarks K; 0 or >= M: every model point (exact)
  double cutoff = 3.5;        // x sigma: pairs farther apart are left out of the E-step (a grid
                              // finds the rest; exp(-3.5^2 / 2) = 0.2% of a coincident pair's
                              // term); 0: every pair
  int threads = 0;            // E-step over the observed points; 0 = all cores (thread_count)
};

/// Throws std::invalid_argument naming the first bad field, prefixed by `prefix`.
void validate(const CpdOptions& options, const std::string& prefix = "");

/// The displacement field found by CPD, in the input units: v(z) = sum_k G(z, l_k) a_k.
struct DisplacementField {
  Points landmarks;                          // K x 3 (input units)
  Eigen::Matrix<double, Eigen::Dynamic, 3> coefficients;  // K x 3 (input units of displacement)
  double beta = 0.0;                         // kernel width (input units)

  /// z + v(z) for every row of `points` (input units).
  Points warp(const Points& points) const;
  /// v(z) for every row.
  Points displacement(const Points& points) const;
};

struct CpdResult {
  Points moved;            // M x 3: the model's points after the warp (= field.warp(Y))
  DisplacementField field;
  double sigma2 = 0.0;     // final variance of the mixture (input units, m^2)
  double residual = 0.0;   // RMS distance (input units) from each observed point to its nearest moved point
  int iterations = 0;
  bool converged = false;  // the variance settled before max_iterations
};

/// Warps `model` (M x 3) onto `observed` (N x 3), both in one frame (after the rigid
/// registration). Throws std::invalid_argument for empty, non-finite or degenerate input
/// (all model points in one place) and for bad options.
CpdResult coherent_point_drift(const Points& model, const Points& observed, const CpdOptions& options = {});

/// Indices of k points of `points` by farthest-point sampling from point 0 (deterministic).
std::vector<int> farthest_points(const Points& points, int k);

}  // namespace bayesgrasp::deform
