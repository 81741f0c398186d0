#include "bayesgrasp/touch/budget.hpp"

#include <cmath>

namespace bayesgrasp::touch {

void BudgetedObjective::operator()(const optim::RowMatrixXd& U, Eigen::VectorXd& f) {
  if (used_ >= budget_ || best_f_ < stop_below_) throw BudgetExhausted{};
  const long long n = std::min<long long>(U.rows(), budget_ - used_);
  f.setConstant(U.rows(), std::numeric_limits<double>::infinity());
  Eigen::VectorXd part(n);
  if (n == U.rows()) {
    fun_(U, part);
  } else {
    fun_(U.topRows(n), part);
  }
  f.head(n) = part;
  used_ += n;
  for (long long i = 0; i < n; ++i) {
    if (std::isfinite(part[i]) && part[i] < best_f_) best_f_ = part[i], best_x_ = U.row(i).transpose();
  }
  trace_n_.push_back(used_);
  trace_f_.push_back(best_f_);
}

}  // namespace bayesgrasp::touch
