// Common types of the optimisers: batch objectives, box bounds, results.
//
// Every optimiser minimises. An objective is evaluated on a batch of candidates at once
// (one row per candidate) so that a swarm, a finite-difference stencil or a line search
// costs one call; the optimisers count the rows they ask for ("evaluations").
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "bayesgrasp/common/checks.hpp"

namespace bayesgrasp::optim {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Batch objective: X is (N, D), one candidate per row; writes f (already sized N).
/// Non-finite values are allowed and treated as +infinity (never the best).
using BatchObjective = std::function<void(const RowMatrixXd& X, Eigen::VectorXd& f)>;

/// Batch residuals for least squares: X is (N, D); writes R (already sized N x n_residuals).
using BatchResiduals = std::function<void(const RowMatrixXd& X, RowMatrixXd& R)>;

/// Axis-aligned box; low <= high elementwise, both finite.
struct Bounds {
  Eigen::VectorXd low, high;
  int dim() const { return static_cast<int>(low.size()); }
  Eigen::VectorXd range() const { return high - low; }
};

/// Throws std::invalid_argument naming the problem (bindings map it to ValueError).
void validate_bounds(const Bounds& b);

/// What the population optimisers (PSO, simulated annealing, firefly) share.
struct PopulationOptions {
  std::uint64_t seed = 0;
  double target = -std::numeric_limits<double>::infinity();  ///< stop once the best value is <= target
  bool record_history = false;
  RowMatrixXd init;  ///< optional (population size, D) starting points (clipped into the box)
};

/// Checks the shared options for a population of n in d dimensions: init empty, or (n, d) and
/// finite. `size_name` names the population size in the message ("n_particles", ...).
void validate_population(const PopulationOptions& o, int n, int d, const char* size_name);
/// The shared fields on their own (target not NaN, init finite); each struct's validate calls it.
void validate_shared(const PopulationOptions& o);

/// What every optimiser reports.
struct Result {
  Eigen::VectorXd x;             ///< best candidate found
  double f = 0.0;                ///< objective at x
  int iterations = 0;            ///< outer iterations done
  long long evaluations = 0;     ///< rows passed to the objective
  std::vector<double> history;   ///< best value after each iteration (if requested)
  bool converged = false;        ///< a tolerance was met (vs. the budget running out)
  std::string message;
};

/// Sets the outcome of a run: best point and value, iterations and evaluations.
void set_outcome(Result& r, const Eigen::VectorXd& best_x, double best_f, int iterations, long long evaluations);

/// Fills a global optimiser's result: set_outcome, and whether the value reached `target` (else
/// the iteration budget was used).
void finish(Result& r, const Eigen::VectorXd& best_x, double best_f, int iterations, long long evaluations,
            double target);

/// Evaluates, counting rows and mapping non-finite values to +inf.
class Evaluator {
 public:
  explicit Evaluator(const BatchObjective& fun) : fun_(fun) {}
  void operator()(const RowMatrixXd& X, Eigen::VectorXd& f);
  /// The objective at one point x (a batch of one row).
  double at(const Eigen::VectorXd& x);
  long long evaluations() const { return n_; }

 private:
  const BatchObjective& fun_;
  long long n_ = 0;
  RowMatrixXd one_;
  Eigen::VectorXd f_one_;
};

/// Standard test functions (batch form), global minimum 0 at the origin (Rosenbrock: at ones).
void sphere(const RowMatrixXd& X, Eigen::VectorXd& f);
void rastrigin(const RowMatrixXd& X, Eigen::VectorXd& f);
void ackley(const RowMatrixXd& X, Eigen::VectorXd& f);
void rosenbrock(const RowMatrixXd& X, Eigen::VectorXd& f);
/// Looks up one of "sphere", "rastrigin", "ackley", "rosenbrock"; throws otherwise.
BatchObjective builtin_objective(const std::string& name);

}  // namespace bayesgrasp::optim
