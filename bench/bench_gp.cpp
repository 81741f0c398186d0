// GP benchmarks (one thread): FITC objective evaluation and training, prediction at 100k
// inputs (mean only; mean + variance), the planners' hot loop (K candidates x P particles),
// and the one-thread Eigen dgemm rate that the FLOP bounds are judged against.
// Data: bench/results/gp_data.npz is produced by bench/gp_peers.py; this binary generates the
// same kind of data itself (seeded) when run standalone, or reads raw .bin files passed via
// BAYESGRASP_GP_DATA (X.bin, y.bin, Z.bin, Xs.bin: float64, row-major, written by run_gp.sh).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>

#include "bayesgrasp/gp/blas.hpp"
#include "bayesgrasp/gp/gp.hpp"

using namespace bayesgrasp::gp;

namespace {

constexpr int N = 5000, D = 3, M = 200, NS = 100000;

Eigen::MatrixXd read_bin(const std::string& path, Eigen::Index rows, Eigen::Index cols) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return {};
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(rows, cols);
  f.read(reinterpret_cast<char*>(m.data()), sizeof(double) * rows * cols);
  if (!f) return {};
  return m;
}

struct Data {
  Eigen::MatrixXd X, Y, Z, Xs;
  Data() {
    const char* dir = std::getenv("BAYESGRASP_GP_DATA");
    if (dir) {
      const std::string d(dir);
      X = read_bin(d + "/X.bin", N, D);
      Y = read_bin(d + "/y.bin", N, 1);
      Z = read_bin(d + "/Z.bin", M, D);
      Xs = read_bin(d + "/Xs.bin", NS, D);
      if (X.size() && Y.size() && Z.size() && Xs.size()) return;
      std::fprintf(stderr, "bench_gp: could not read %s/*.bin, generating data\n", dir);
    }
    std::mt19937_64 rng(0);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::normal_distribution<double> nd(0.0, 0.1);
    X.resize(N, D);
    Y.resize(N, 1);
    for (int i = 0; i < N; ++i) {
      for (int d = 0; d < D; ++d) X(i, d) = U(rng);
      Y(i, 0) = std::sin(6 * X(i, 0)) * std::cos(4 * X(i, 1)) + X(i, 2) * X(i, 2) + nd(rng);
    }
    Z = X.topRows(M);
    Xs.resize(NS, D);
    for (int i = 0; i < NS; ++i)
      for (int d = 0; d < D; ++d) Xs(i, d) = U(rng);
  }
};

const Data& data() {
  static const Data d;
  return d;
}

// FITC on the raw data (no normalisation) with the fixed inducing inputs, from unit
// hyper-parameters; optimised or not.
GPOptions fitc_options(bool optimize) {
  GPOptions o;
  o.inducing = data().Z;
  o.optimize = optimize;
  o.normalize_x = o.normalize_y = false;
  o.lengthscale = Eigen::VectorXd::Ones(1);
  o.variance = o.noise = 1.0;
  return o;
}

const SparseGP& fitted_fitc() {
  static SparseGP gp = [] {
    SparseGP g(fitc_options(true));
    g.fit(data().X, data().Y);
    return g;
  }();
  return gp;
}

void BM_dgemm_eigen(benchmark::State& st) {
  // (M x N) * (N x M) at the FITC sizes, the operation the objective's cost is made of.
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(M, N), B = Eigen::MatrixXd::Random(N, M);
  Eigen::MatrixXd C(M, M);
  for (auto _ : st) {
    C.noalias() = A * B;
    benchmark::DoNotOptimize(C.data());
  }
  st.counters["GFLOPs"] = benchmark::Counter(2.0 * M * N * M, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_dgemm_eigen)->Unit(benchmark::kMillisecond)->MinTime(0.5);

void BM_dgemm_blas(benchmark::State& st) {
  // The same product through the BLAS the FITC objective links (OpenBLAS): the FLOP bounds are
  // taken at the faster of the two rates.
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(M, N), B = Eigen::MatrixXd::Random(N, M);
  Eigen::MatrixXd C(M, M);
  for (auto _ : st) {
    bayesgrasp::gp::blas::gemm(blas::Op::None, blas::Op::None, 1.0, A, B, 0.0, C);
    benchmark::DoNotOptimize(C.data());
  }
  st.counters["GFLOPs"] = benchmark::Counter(2.0 * M * N * M, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_dgemm_blas)->Unit(benchmark::kMillisecond)->MinTime(0.5);

void BM_fitc_objective(benchmark::State& st) {
  SparseGP gp(fitc_options(false));
  gp.fit(data().X, data().Y);
  const Eigen::VectorXd th = fitted_fitc().parameters();
  Eigen::VectorXd g;
  for (auto _ : st) benchmark::DoNotOptimize(gp.objective(th, g));
  st.counters["bound_3NM2_GFLOP"] = 3.0 * N * M * M * 1e-9;
}
BENCHMARK(BM_fitc_objective)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_fitc_train(benchmark::State& st) {
  double lml = 0;
  int evals = 0;
  for (auto _ : st) {
    SparseGP gp(fitc_options(true));
    gp.fit(data().X, data().Y);
    lml = gp.log_marginal_likelihood();
    evals = gp.fit_info().evaluations;
  }
  st.counters["lml"] = lml;
  st.counters["evaluations"] = evals;
}
BENCHMARK(BM_fitc_train)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_fitc_predict_mean_100k(benchmark::State& st) {
  const SparseGP& gp = fitted_fitc();
  for (auto _ : st) benchmark::DoNotOptimize(gp.predict_mean(data().Xs).data());
  st.counters["inputs_per_s"] = benchmark::Counter(NS, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_fitc_predict_mean_100k)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_fitc_predict_mean_var_100k(benchmark::State& st) {
  const SparseGP& gp = fitted_fitc();
  Eigen::MatrixXd m, v;
  for (auto _ : st) {
    gp.predict(data().Xs, m, v);
    benchmark::DoNotOptimize(v.data());
  }
  st.counters["bound_2M2_GFLOP"] = 2.0 * M * M * NS * 1e-9;
}
BENCHMARK(BM_fitc_predict_mean_var_100k)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The same prediction through the blockwise Eigen path (kernel block, TRMM with the triangular
// factor, row norms): the fused kernel's gain measured against it in the same run.
struct BlockwiseFitc : SparseGP {
  explicit BlockwiseFitc(const SparseGP& g) : SparseGP(g) { cache_.G_packed.clear(); }
};

void BM_fitc_predict_mean_var_100k_blockwise(benchmark::State& st) {
  static const BlockwiseFitc gp(fitted_fitc());
  Eigen::MatrixXd m, v, mf, vf;
  fitted_fitc().predict(data().Xs, mf, vf);
  for (auto _ : st) {
    gp.predict(data().Xs, m, v);
    benchmark::DoNotOptimize(v.data());
  }
  // agreement of the fused and blockwise paths, relative to the prior variance
  st.counters["max_abs_var_diff_rel_prior"] = (v - vf).cwiseAbs().maxCoeff() / std::exp(gp.kernel().log_variance);
  st.counters["max_abs_mean_diff"] = (m - mf).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_fitc_predict_mean_var_100k_blockwise)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// Planners' hot loop: K candidates x P particles -> one GP mean per pair. The caller builds the
// (K*P, 3) relative inputs; we time building them (a planar transform) plus the mean.
void BM_hot_loop_pairs(benchmark::State& st) {
  const SparseGP& gp = fitted_fitc();
  const int K = static_cast<int>(st.range(0)), P = 500;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Eigen::MatrixXd cand(K, 3), part(P, 3);
  for (int i = 0; i < K; ++i) cand.row(i) << U(rng), U(rng), U(rng);
  for (int j = 0; j < P; ++j) part.row(j) << 0.05 * U(rng), 0.05 * U(rng), 0.1 * U(rng);
  Eigen::MatrixXd Xin(K * P, 3);
  for (auto _ : st) {
    for (int i = 0; i < K; ++i)
      for (int j = 0; j < P; ++j) Xin.row(i * P + j) = cand.row(i) - part.row(j);
    benchmark::DoNotOptimize(gp.predict_mean(Xin).data());
  }
  st.counters["pairs_per_s"] = benchmark::Counter(double(K) * P, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_hot_loop_pairs)->Arg(20)->Arg(200)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_exact_predict_mean_var(benchmark::State& st) {
  // Exact GP at N = 2000 training points, 10,000 prediction inputs (the scikit-learn comparison).
  static ExactGP gp = [] {
    GPOptions o = fitc_options(false);
    o.inducing.resize(0, 0);
    ExactGP g(o);
    g.fit(data().X.topRows(2000), data().Y.topRows(2000));
    return g;
  }();
  const Eigen::MatrixXd Xs = data().Xs.topRows(10000);
  Eigen::MatrixXd m, v;
  for (auto _ : st) {
    gp.predict(Xs, m, v);
    benchmark::DoNotOptimize(v.data());
  }
}
BENCHMARK(BM_exact_predict_mean_var)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
