// Coherent Point Drift, non-rigid (cpd.hpp): the EM loop and its named steps.
#include "bayesgrasp/deform/cpd.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <stdexcept>
#include <vector>

#include "bayesgrasp/common/checks.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::deform {

void validate(const CpdOptions& o, const std::string& prefix) {
  require_positive(o.beta, prefix + "beta");
  require_positive(o.lam, prefix + "lam");
  if (!(o.outlier_weight >= 0.0 && o.outlier_weight < 1.0))
    bad_field(prefix + "outlier_weight", "in [0, 1)", number_str(o.outlier_weight));
  require_at_least(o.max_iterations, 1, prefix + "max_iterations");
  require_non_negative(o.tolerance, prefix + "tolerance");
  require_at_least(o.rank, 0, prefix + "rank");
  require_non_negative(o.cutoff, prefix + "cutoff");
  thread_count(o.threads, (prefix + "threads").c_str());
}

namespace {

using Matrix = Eigen::MatrixXd;
using Disp = Eigen::Matrix<double, Eigen::Dynamic, 3>;

void check_points(const Points& P, const char* name) {
  if (P.rows() == 0) throw std::invalid_argument(std::string(name) + ": is empty");
  if (!P.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
}

/// The one normalisation of both sets: the model's centroid and RMS radius.
struct Frame {
  Eigen::RowVector3d center;
  double scale = 1.0;
  Points to(const Points& P) const { return (P.rowwise() - center) / scale; }
  Points from(const Points& P) const { return (P * scale).rowwise() + center; }
};

Frame frame_of(const Points& model) {
  Frame f;
  f.center = model.colwise().mean();
  f.scale = std::sqrt((model.rowwise() - f.center).rowwise().squaredNorm().mean());
  if (!(f.scale > 1e-12)) throw std::invalid_argument("model: all its points are in one place");
  return f;
}

/// G(A, B)_ij = exp(-|a_i - b_j|^2 / (2 beta^2)).
Matrix kernel(const Points& A, const Points& B, double beta) {
  Matrix K(A.rows(), B.rows());
  const double g = -0.5 / (beta * beta);
  for (Eigen::Index i = 0; i < A.rows(); ++i)
    for (Eigen::Index j = 0; j < B.rows(); ++j) K(i, j) = std::exp(g * (A.row(i) - B.row(j)).squaredNorm());
  return K;
}

/// The sums of the E-step's posterior P (M x N) that the M-step needs; P itself is never stored.
struct Posterior {
  Eigen::VectorXd P1;  // M: P 1
  Eigen::VectorXd Pt1; // N: P^T 1
  Disp PX;             // M x 3: P X
  double NP = 0.0;     // 1^T P 1
};

/// The moved model's points binned in cubes of side `cell` (their neighbours within `cell` of a
/// query lie in the 27 cubes around it); empty when the cubes would be too few to save anything.
struct Grid {
  double cell = 0.0;
  Eigen::RowVector3d lo;
  std::vector<std::pair<std::int64_t, int>> keyed;  // (cube key, point), sorted by key

  static std::int64_t key(long i, long j, long k) { return (i * 4096 + j) * 4096 + k; }
  Eigen::Array3i cube(const Eigen::RowVector3d& p) const {
    return ((p - lo).array() / cell).floor().cast<int>().transpose();
  }

  Grid(const Points& T, double cutoff_distance) {
    const Eigen::RowVector3d hi = T.colwise().maxCoeff();
    lo = T.colwise().minCoeff();
    if (!(cutoff_distance > 0.0) || cutoff_distance * 3.0 > (hi - lo).maxCoeff()) return;  // too coarse: every pair
    // cubes no smaller than 1/2000 of the extent keep the keys apart (4096 per axis); a larger
    // cube still holds every neighbour within the cutoff in the 27 around a point, and a key
    // shared by a far point costs a distance, never a wrong term (each pair's distance is checked)
    cell = std::max(cutoff_distance, (hi - lo).maxCoeff() / 2000.0);
    keyed.reserve(T.rows());
    for (Eigen::Index m = 0; m < T.rows(); ++m) {
      const Eigen::Array3i c = cube(T.row(m));
      keyed.emplace_back(key(c(0), c(1), c(2)), int(m));
    }
    std::sort(keyed.begin(), keyed.end());
  }
  bool used() const { return cell > 0.0; }

  /// Calls f(m) for every point in the 27 cubes around p.
  template <class F>
  void near(const Eigen::RowVector3d& p, F&& f) const {
    const Eigen::Array3i c = cube(p);
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          const std::int64_t q = key(c(0) + i, c(1) + j, c(2) + k);
          auto it = std::lower_bound(keyed.begin(), keyed.end(), std::make_pair(q, -1));
          for (; it != keyed.end() && it->first == q; ++it) f(it->second);
        }
  }
};

/// E-step: posteriors of the moved model's components for every observed point, with the
/// uniform outlier term c, accumulated per thread over the observed points. With a cutoff, only
/// the components within cutoff * sigma of a point are summed (found through a Grid).
Posterior e_step(const Points& X, const Points& T, double sigma2, double w, double cutoff, int threads) {
  const long N = X.rows(), M = T.rows();
  const double c = std::pow(2.0 * M_PI * sigma2, 1.5) * w / (1.0 - w) * double(M) / double(N);
  const double g = -0.5 / sigma2;
  const double r2 = cutoff * cutoff * sigma2;
  const Grid grid(T, cutoff * std::sqrt(sigma2));
  const int nt = thread_count_for(threads, N);
  std::vector<Eigen::VectorXd> P1s(nt, Eigen::VectorXd::Zero(M));
  std::vector<Disp> PXs(nt, Disp::Zero(M, 3));
  Posterior out;
  out.Pt1 = Eigen::VectorXd::Zero(N);
#pragma omp parallel num_threads(nt)
  {
    const int t = omp_get_thread_num();
    Eigen::VectorXd k(M);
    std::vector<std::pair<int, double>> terms;
#pragma omp for schedule(static)
    for (long n = 0; n < N; ++n) {
      const Eigen::RowVector3d x = X.row(n);
      if (!grid.used()) {
        for (long m = 0; m < M; ++m) k(m) = std::exp(g * (x - T.row(m)).squaredNorm());
        const double den = k.sum() + c;
        if (!(den > 0.0)) continue;
        k /= den;
        P1s[t] += k;
        PXs[t].noalias() += k * x;
        out.Pt1(n) = k.sum();
        continue;
      }
      terms.clear();
      double sum = 0.0;
      grid.near(x, [&](int m) {
        const double d2 = (x - T.row(m)).squaredNorm();
        if (d2 <= r2) {
          const double e = std::exp(g * d2);
          terms.emplace_back(m, e);
          sum += e;
        }
      });
      const double den = sum + c;
      if (!(den > 0.0)) continue;
      for (const auto& [m, e] : terms) {
        const double p = e / den;
        P1s[t](m) += p;
        PXs[t].row(m) += p * x;
      }
      out.Pt1(n) = sum / den;
    }
  }
  out.P1 = Eigen::VectorXd::Zero(M);
  out.PX = Disp::Zero(M, 3);
  for (int t = 0; t < nt; ++t) {
    out.P1 += P1s[t];
    out.PX += PXs[t];
  }
  out.NP = out.P1.sum();
  return out;
}

/// M-step for the field: with G ~ C L^-1 C^T, D = d(P1), s = lambda sigma2 and B = P X - D Y,
/// (D G + s I) W = B is solved by Woodbury; its coefficients a = L^-1 C^T W come out as
/// a = (s L + C^T D C)^-1 C^T B without inverting L (C^T W = L a follows from the solution).
Disp field_coefficients(const Matrix& C, const Matrix& L, const Posterior& post, const Points& Y, double s) {
  const Disp B = post.PX - post.P1.asDiagonal() * Disp(Y);
  Matrix A = s * L + C.transpose() * post.P1.asDiagonal() * C;
  A.diagonal().array() += 1e-12 * std::max(1.0, A.diagonal().mean());  // L may be near-singular for wide kernels
  return A.ldlt().solve(C.transpose() * B);
}

/// M-step for the variance (Eq. of Fig. 4), floored so that exp() stays defined.
double variance(const Points& X, const Points& T, const Posterior& post) {
  const double xx = (post.Pt1.array() * X.rowwise().squaredNorm().array()).sum();
  const double xt = (post.PX.array() * T.array()).sum();
  const double tt = (post.P1.array() * T.rowwise().squaredNorm().array()).sum();
  return std::max((xx - 2.0 * xt + tt) / (3.0 * post.NP), 1e-12);
}

/// Initial variance: the mean squared distance over all pairs / 3.
double initial_variance(const Points& X, const Points& Y) {
  const double N = double(X.rows()), M = double(Y.rows());
  const Eigen::RowVector3d sx = X.colwise().sum(), sy = Y.colwise().sum();
  const double s = N * Y.rowwise().squaredNorm().sum() + M * X.rowwise().squaredNorm().sum() - 2.0 * sx.dot(sy);
  return std::max(s / (3.0 * M * N), 1e-12);
}

double rms_nearest(const Points& X, const Points& T) {
  double s = 0.0;
  for (Eigen::Index n = 0; n < X.rows(); ++n) s += (T.rowwise() - X.row(n)).rowwise().squaredNorm().minCoeff();
  return std::sqrt(s / double(X.rows()));
}

}  // namespace

Points DisplacementField::displacement(const Points& points) const {
  if (landmarks.rows() == 0) return Points::Zero(points.rows(), 3);
  return Points(kernel(points, landmarks, beta) * coefficients);
}

Points DisplacementField::warp(const Points& points) const { return points + displacement(points); }

CpdResult coherent_point_drift(const Points& model, const Points& observed, const CpdOptions& options) {
  validate(options);
  check_points(model, "model");
  check_points(observed, "observed");
  const Frame f = frame_of(model);
  const Points Y = f.to(model), X = f.to(observed);
  const long M = Y.rows();
  const int K = (options.rank == 0 || options.rank >= M) ? int(M) : options.rank;
  const std::vector<int> idx = farthest_points(Y, K);
  Points landmarks(idx.size(), 3);
  for (std::size_t k = 0; k < idx.size(); ++k) landmarks.row(k) = Y.row(idx[k]);
  const Matrix C = kernel(Y, landmarks, options.beta), L = kernel(landmarks, landmarks, options.beta);

  CpdResult r;
  Points T = Y;
  Disp a = Disp::Zero(landmarks.rows(), 3);
  double sigma2 = initial_variance(X, Y);
  for (r.iterations = 1; r.iterations <= options.max_iterations; ++r.iterations) {
    const Posterior post = e_step(X, T, sigma2, options.outlier_weight, options.cutoff, options.threads);
    if (!(post.NP > 1e-12)) break;  // nothing observed is explained by the model any more
    a = field_coefficients(C, L, post, Y, options.lam * sigma2);
    T = Y + C * a;
    const double next = variance(X, T, post);
    const bool settled = std::abs(next - sigma2) <= options.tolerance * sigma2;
    sigma2 = next;
    if (settled) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(r.iterations, options.max_iterations);
  r.field.landmarks = f.from(landmarks);
  r.field.coefficients = a * f.scale;
  r.field.beta = options.beta * f.scale;
  r.moved = f.from(T);
  r.sigma2 = sigma2 * f.scale * f.scale;
  r.residual = rms_nearest(observed, r.moved);
  return r;
}

}  // namespace bayesgrasp::deform
