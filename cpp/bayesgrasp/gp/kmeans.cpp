#include "bayesgrasp/gp/kmeans.hpp"

#include <random>
#include <stdexcept>
#include <vector>

namespace bayesgrasp::gp {

namespace {

// k-means++ seeding: the first centre uniformly, each next one with probability proportional to
// the squared distance to the nearest centre chosen so far. Stops early when every point is a
// centre already (fewer distinct points than k).
Eigen::MatrixXd seed_centres(const Eigen::MatrixXd& X, int k, std::uint64_t seed) {
  const Eigen::Index N = X.rows(), D = X.cols();
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Index> chosen;
  chosen.push_back(std::uniform_int_distribution<Eigen::Index>(0, N - 1)(rng));
  Eigen::ArrayXd d2 = (X.rowwise() - X.row(chosen[0])).rowwise().squaredNorm().array();
  std::uniform_real_distribution<double> U(0.0, 1.0);
  while (static_cast<int>(chosen.size()) < k) {
    const double total = d2.sum();
    if (!(total > 0.0)) break;
    double u = U(rng) * total, acc = 0.0;
    Eigen::Index pick = -1;
    for (Eigen::Index i = 0; i < N; ++i) {
      acc += d2[i];
      if (d2[i] > 0.0) pick = i;
      if (acc >= u && d2[i] > 0.0) break;
    }
    chosen.push_back(pick);
    d2 = d2.min((X.rowwise() - X.row(pick)).rowwise().squaredNorm().array());
  }
  const Eigen::Index K = static_cast<Eigen::Index>(chosen.size());
  Eigen::MatrixXd C(K, D);
  for (Eigen::Index c = 0; c < K; ++c) C.row(c) = X.row(chosen[c]);
  return C;
}

// One Lloyd iteration: assign every point to its nearest centre, move each centre to the mean
// of its points (an empty cluster keeps its centre).
void lloyd_step(const Eigen::MatrixXd& X, Eigen::MatrixXd& C, Eigen::VectorXi& assign) {
  const Eigen::Index N = X.rows(), D = X.cols(), K = C.rows();
  for (Eigen::Index i = 0; i < N; ++i) {
    Eigen::Index best;
    (C.rowwise() - X.row(i)).rowwise().squaredNorm().minCoeff(&best);
    assign[i] = static_cast<int>(best);
  }
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(K, D);
  Eigen::VectorXd cnt = Eigen::VectorXd::Zero(K);
  for (Eigen::Index i = 0; i < N; ++i) {
    S.row(assign[i]) += X.row(i);
    cnt[assign[i]] += 1.0;
  }
  for (Eigen::Index c = 0; c < K; ++c)
    if (cnt[c] > 0) C.row(c) = S.row(c) / cnt[c];
}

}  // namespace

Eigen::MatrixXd kmeans_pp(const Eigen::MatrixXd& X, int k, std::uint64_t seed, int iters) {
  if (X.rows() == 0 || k <= 0) throw std::invalid_argument("kmeans_pp: need points and k >= 1");
  Eigen::MatrixXd C = seed_centres(X, k, seed);
  Eigen::VectorXi assign(X.rows());
  for (int it = 0; it < iters; ++it) lloyd_step(X, C, assign);
  return C;
}

}  // namespace bayesgrasp::gp
