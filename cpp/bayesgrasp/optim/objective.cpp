#include "bayesgrasp/optim/objective.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bayesgrasp/common/checks.hpp"

namespace bayesgrasp::optim {

void validate_bounds(const Bounds& b) {
  if (b.low.size() == 0) throw std::invalid_argument("bounds: dimension must be at least 1");
  if (b.low.size() != b.high.size())
    throw std::invalid_argument("bounds: low and high have different lengths");
  if (!b.low.allFinite() || !b.high.allFinite())
    throw std::invalid_argument("bounds: contains NaN or infinity");
  for (int i = 0; i < b.dim(); ++i)
    if (b.low[i] > b.high[i])
      throw std::invalid_argument("bounds: low > high in dimension " + std::to_string(i));
}

void validate_shared(const PopulationOptions& o) {
  require_not_nan(o.target, "target");
  if (!o.init.allFinite()) throw std::invalid_argument("init: contains NaN or infinity");
}

void validate_population(const PopulationOptions& o, int n, int d, const char* size_name) {
  // n x d positions, velocities and bests: 10^8 values are GBs; more only exhausts memory.
  if (static_cast<long long>(n) * std::max(d, 1) > 100000000LL)
    throw std::invalid_argument(std::string(size_name) + ": " + std::to_string(n) + " x " + std::to_string(d) +
                                " dimensions exceed 10^8 values");
  if (o.init.size() == 0) return;
  if (o.init.rows() != n || o.init.cols() != d)
    throw std::invalid_argument(std::string("init: expected shape (") + size_name + ", D) = (" + std::to_string(n) +
                                ", " + std::to_string(d) + "), got (" + std::to_string(o.init.rows()) + ", " +
                                std::to_string(o.init.cols()) + ")");
  if (!o.init.allFinite()) throw std::invalid_argument("init: contains NaN or infinity");
}

double Evaluator::at(const Eigen::VectorXd& x) {
  one_.resize(1, x.size());
  one_.row(0) = x.transpose();
  (*this)(one_, f_one_);
  return f_one_[0];
}

void Evaluator::operator()(const RowMatrixXd& X, Eigen::VectorXd& f) {
  f.resize(X.rows());
  fun_(X, f);
  n_ += X.rows();
  for (Eigen::Index i = 0; i < f.size(); ++i)
    if (!std::isfinite(f[i])) f[i] = std::numeric_limits<double>::infinity();
}

void sphere(const RowMatrixXd& X, Eigen::VectorXd& f) { f = X.rowwise().squaredNorm(); }

void rastrigin(const RowMatrixXd& X, Eigen::VectorXd& f) {
  const double two_pi = 2.0 * M_PI;
  f.resize(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    double s = 10.0 * X.cols();
    for (Eigen::Index d = 0; d < X.cols(); ++d) s += X(i, d) * X(i, d) - 10.0 * std::cos(two_pi * X(i, d));
    f[i] = s;
  }
}

void ackley(const RowMatrixXd& X, Eigen::VectorXd& f) {
  const double two_pi = 2.0 * M_PI;
  const double n = static_cast<double>(X.cols());
  f.resize(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    double s2 = 0.0, sc = 0.0;
    for (Eigen::Index d = 0; d < X.cols(); ++d) {
      s2 += X(i, d) * X(i, d);
      sc += std::cos(two_pi * X(i, d));
    }
    f[i] = -20.0 * std::exp(-0.2 * std::sqrt(s2 / n)) - std::exp(sc / n) + 20.0 + M_E;
  }
}

void rosenbrock(const RowMatrixXd& X, Eigen::VectorXd& f) {
  f.resize(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    double s = 0.0;
    for (Eigen::Index d = 0; d + 1 < X.cols(); ++d) {
      const double a = X(i, d + 1) - X(i, d) * X(i, d), b = 1.0 - X(i, d);
      s += 100.0 * a * a + b * b;
    }
    f[i] = s;
  }
}

BatchObjective builtin_objective(const std::string& name) {
  if (name == "sphere") return sphere;
  if (name == "rastrigin") return rastrigin;
  if (name == "ackley") return ackley;
  if (name == "rosenbrock") return rosenbrock;
  throw std::invalid_argument("objective: unknown built-in '" + name +
                              "' (expected sphere, rastrigin, ackley or rosenbrock)");
}

void set_outcome(Result& r, const Eigen::VectorXd& best_x, double best_f, int iterations, long long evaluations) {
  r.x = best_x;
  r.f = best_f;
  r.iterations = iterations;
  r.evaluations = evaluations;
}

void finish(Result& r, const Eigen::VectorXd& best_x, double best_f, int iterations, long long evaluations,
            double target) {
  set_outcome(r, best_x, best_f, iterations, evaluations);
  r.converged = best_f <= target;
  r.message = r.converged ? "target reached" : "iteration budget used";
}

}  // namespace bayesgrasp::optim
