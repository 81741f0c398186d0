// An evaluation budget shared by every optimiser of a touch estimate: the objective is counted
// row by row, the best candidate seen is kept, and the best value after each batch is the
// optimiser's trace. Once the budget is used up, a further call throws BudgetExhausted (the
// restarting local optimisers stop there; the population optimisers are sized to fit it).
// With a stop level s > 0, a call made once the best value is below s throws as well: the search
// has reproduced the readings to that level and ends early.
#pragma once

#include <functional>
#include <limits>
#include <vector>

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::touch {

struct BudgetExhausted {};

class BudgetedObjective {
 public:
  BudgetedObjective(optim::BatchObjective fun, long long budget, double stop_below = 0.0)
      : fun_(std::move(fun)), budget_(budget), stop_below_(stop_below) {}

  /// Evaluates the rows of U that fit in the budget (the rest get +inf); throws BudgetExhausted
  /// if nothing is left or the best value so far is below the stop level.
  void operator()(const optim::RowMatrixXd& U, Eigen::VectorXd& f);
  /// This objective as the optimisers take it (a reference: it must outlive the run).
  optim::BatchObjective objective() {
    return [this](const optim::RowMatrixXd& U, Eigen::VectorXd& f) { (*this)(U, f); };
  }

  long long used() const { return used_; }
  long long remaining() const { return budget_ - used_; }
  /// Whether the search ended at the stop level (before its budget was used).
  bool stopped() const { return best_f_ < stop_below_; }
  const Eigen::VectorXd& best_x() const { return best_x_; }
  double best_f() const { return best_f_; }
  /// After each call: evaluations so far and the best value so far.
  const std::vector<long long>& trace_evaluations() const { return trace_n_; }
  const std::vector<double>& trace_best() const { return trace_f_; }

 private:
  optim::BatchObjective fun_;
  long long budget_, used_ = 0;
  double stop_below_;
  Eigen::VectorXd best_x_;
  double best_f_ = std::numeric_limits<double>::infinity();
  std::vector<long long> trace_n_;
  std::vector<double> trace_f_;
};

}  // namespace bayesgrasp::touch
