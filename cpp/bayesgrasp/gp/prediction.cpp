#include "bayesgrasp/gp/prediction.hpp"

#include <algorithm>
#include <cstdlib>
#include <new>

#include "bayesgrasp/gp/prediction_kernels.hpp"

namespace bayesgrasp::gp {

namespace {
using namespace detail;  // prediction_kernels.hpp, vector_exp.hpp

constexpr int kBlock = 128;  // inputs per block of the blockwise (Eigen) path

int threads_for(Eigen::Index n, int threads) { return n >= kParallelPredictionMin ? std::max(1, threads) : 1; }

// The kernel-vector buffer of a group of inputs (M x kGroup), aligned to 64 bytes (the widest
// SIMD vector): Eigen's vectorised Matern shape in shape_group then evaluates every element the
// same way whatever the allocation's address (an unaligned start is peeled in scalar code).
class GroupBuffer {
 public:
  explicit GroupBuffer(Eigen::Index M) {
    const std::size_t bytes = static_cast<std::size_t>(M) * kGroup * sizeof(double);
    data_ = static_cast<double*>(std::aligned_alloc(64, (bytes + 63) / 64 * 64));
    if (!data_) throw std::bad_alloc();
  }
  ~GroupBuffer() { std::free(data_); }
  GroupBuffer(const GroupBuffer&) = delete;
  GroupBuffer& operator=(const GroupBuffer&) = delete;
  double* data() { return data_; }

 private:
  double* data_ = nullptr;
};

// F (M x n): kernel shape between the cache basis and n raw inputs (rows i0.. of X).
void shape_block(const PredictionCache& c, const Eigen::MatrixXd& X, Eigen::Index i0, Eigen::Index n,
                 Eigen::MatrixXd& F) {
  const Eigen::Index D = c.basis.cols();
  F.resize(c.basis.rows(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    auto f = F.col(j).array();
    f = (c.basis.col(0).array() - X(i0 + j, 0) * c.inv_ls[0]).square();
    for (Eigen::Index d = 1; d < D; ++d) f += (c.basis.col(d).array() - X(i0 + j, d) * c.inv_ls[d]).square();
  }
  if (c.type == KernelType::SquaredExponential) {
    F.array() = (-0.5 * F.array()).exp();
  } else {
    for (Eigen::Index j = 0; j < n; ++j) {
      auto f = F.col(j).array();
      const Eigen::ArrayXd s = (5.0 * f).sqrt();
      f = (1.0 + s + s.square() * (1.0 / 3.0)) * (-s).exp();
    }
  }
}

// H = G F or G^-1 F, as the cache's variance factor says.
void apply_factor(const PredictionCache& c, const Eigen::MatrixXd& F, Eigen::MatrixXd& H) {
  switch (c.factor) {
    case VarianceFactor::Upper: H.noalias() = c.G.triangularView<Eigen::Upper>() * F; break;
    case VarianceFactor::InverseLower: H = c.G.triangularView<Eigen::Lower>().solve(F); break;
  }
}

// Fused path (factor Upper, packed): groups of kGroup inputs, kernel vectors in a small buffer,
// mean and |G f|^2 accumulated in registers.
void predict_fused(const PredictionCache& c, const Eigen::MatrixXd& X, Predictive what, int threads,
                   Eigen::MatrixXd& mean, Eigen::MatrixXd& var) {
  const Eigen::Index N = X.rows(), P = c.alpha.cols();
  const bool include_noise = what == Predictive::Observation;
  const Eigen::Index M = c.basis.rows();
  const Eigen::Index ngroups = (N + kGroup - 1) / kGroup;
#pragma omp parallel num_threads(threads_for(N, threads))
  {
    GroupBuffer F(M);
    alignas(64) double q[kGroup], m[kGroup];
#pragma omp for schedule(static)
    for (Eigen::Index g = 0; g < ngroups; ++g) {
      const Eigen::Index i0 = g * kGroup;
      const int n = static_cast<int>(std::min<Eigen::Index>(kGroup, N - i0));
      shape_group(c, X, i0, n, F.data());
      for (Eigen::Index p = 0; p < P; ++p) {
        mean_group(c.alpha.col(p).data(), M, F.data(), m);
        for (int j = 0; j < n; ++j) mean(i0 + j, p) = m[j] + c.offset[p];
      }
      quad_group(c.G_packed.data(), M, F.data(), q);
      for (int j = 0; j < n; ++j) {
        const double v = std::max(1.0 - q[j], 0.0);  // never negative, NaN-free for finite F
        for (Eigen::Index p = 0; p < P; ++p) var(i0 + j, p) = v * c.var_f0[p] + (include_noise ? c.noise[p] : 0.0);
      }
    }
  }
}

// Blockwise path: kernel blocks of kBlock inputs, the mean by one product, the variance through
// apply_factor and column norms.
void predict_blockwise(const PredictionCache& c, const Eigen::MatrixXd& X, Predictive what, int threads,
                       Eigen::MatrixXd& mean, Eigen::MatrixXd& var) {
  const Eigen::Index N = X.rows(), P = c.alpha.cols();
  const Eigen::Index nblocks = (N + kBlock - 1) / kBlock;
#pragma omp parallel num_threads(threads_for(N, threads))
  {
    Eigen::MatrixXd F, H;
    Eigen::ArrayXd v;
#pragma omp for schedule(static)
    for (Eigen::Index b = 0; b < nblocks; ++b) {
      const Eigen::Index i0 = b * kBlock, n = std::min<Eigen::Index>(kBlock, N - i0);
      shape_block(c, X, i0, n, F);
      mean.middleRows(i0, n).noalias() = F.transpose() * c.alpha;
      mean.middleRows(i0, n).rowwise() += c.offset;
      apply_factor(c, F, H);
      v = (1.0 - H.colwise().squaredNorm().array()).max(0.0).transpose();
      for (Eigen::Index p = 0; p < P; ++p) {
        var.col(p).segment(i0, n) = (v * c.var_f0[p]).matrix();
        if (what == Predictive::Observation) var.col(p).segment(i0, n).array() += c.noise[p];
      }
    }
  }
}

}  // namespace

void PredictionCache::pack_factor() {
  G_packed.clear();
  if (factor == VarianceFactor::Upper && G.rows() == G.cols() && G.rows() == basis.rows()) G_packed = pack_upper(G);
}

Eigen::MatrixXd predict_mean(const PredictionCache& c, const Eigen::MatrixXd& X, int threads) {
  const Eigen::Index N = X.rows(), P = c.alpha.cols();
  Eigen::MatrixXd out(N, P);
  // Groups of kGroup inputs: kernel vectors in a small buffer (own vectorised exp), then the
  // weighted sums in registers, as in the fused mean + variance path.
  const Eigen::Index M = c.basis.rows();
  const Eigen::Index ngroups = (N + kGroup - 1) / kGroup;
#pragma omp parallel num_threads(threads_for(N, threads))
  {
    GroupBuffer F(M);
    alignas(64) double m[kGroup];
#pragma omp for schedule(static)
    for (Eigen::Index g = 0; g < ngroups; ++g) {
      const Eigen::Index i0 = g * kGroup;
      const int n = static_cast<int>(std::min<Eigen::Index>(kGroup, N - i0));
      if (P == 1 && mean_group_se(c, X, i0, n, c.alpha.data(), m)) {
        for (int j = 0; j < n; ++j) out(i0 + j, 0) = m[j] + c.offset[0];
        continue;
      }
      shape_group(c, X, i0, n, F.data());
      for (Eigen::Index p = 0; p < P; ++p) {
        mean_group(c.alpha.col(p).data(), M, F.data(), m);
        for (int j = 0; j < n; ++j) out(i0 + j, p) = m[j] + c.offset[p];
      }
    }
  }
  return out;
}

void predict_mean_var(const PredictionCache& c, const Eigen::MatrixXd& X, Predictive what, int threads,
                      Eigen::MatrixXd& mean, Eigen::MatrixXd& var) {
  mean.resize(X.rows(), c.alpha.cols());
  var.resize(X.rows(), c.alpha.cols());
  if (c.factor == VarianceFactor::Upper && !c.G_packed.empty())
    predict_fused(c, X, what, threads, mean, var);
  else
    predict_blockwise(c, X, what, threads, mean, var);
}

Eigen::MatrixXd predict_cov(const PredictionCache& c, const Eigen::MatrixXd& X, int output, Predictive what) {
  Eigen::MatrixXd F;
  shape_block(c, X, 0, X.rows(), F);
  Eigen::MatrixXd H;
  apply_factor(c, F, H);
  Eigen::MatrixXd Xs = X.array().rowwise() * c.inv_ls.transpose().array();
  Eigen::MatrixXd Kxx = detail::sq_dist(Xs, Xs);
  Kernel k;
  k.type = c.type;
  k.shape_inplace(Kxx);
  Kxx.noalias() -= H.transpose() * H;
  Kxx *= c.var_f0[output];
  if (what == Predictive::Observation) Kxx.diagonal().array() += c.noise[output];
  return Kxx;
}

}  // namespace bayesgrasp::gp
