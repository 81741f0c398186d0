#include "bayesgrasp/touch/search_space.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::touch {

void validate(const SearchBox& b) {
  if (!(b.xy > 0.0) || !std::isfinite(b.xy))
    throw std::invalid_argument("box.xy: must be positive and finite, got " + std::to_string(b.xy));
  if (!(b.yaw > 0.0) || !(b.yaw <= M_PI))
    throw std::invalid_argument("box.yaw: must lie in (0, pi], got " + std::to_string(b.yaw));
  if (!(b.scale_low > 0.0) || !(b.scale_high > b.scale_low) || !std::isfinite(b.scale_high))
    throw std::invalid_argument("box.scale_low, box.scale_high: need 0 < scale_low < scale_high < inf");
}

SearchSpace::SearchSpace(Unknowns unknowns, const State& initial, const SearchBox& box)
    : unknowns_(unknowns), initial_(initial) {
  validate(box);
  if (!initial.allFinite()) throw std::invalid_argument("initial: contains NaN or infinity");
  if (!(initial[3] > 0.0)) throw std::invalid_argument("initial: the scale must be positive");
  switch (unknowns) {
    case Unknowns::Pose: free_ = {0, 1, 2}; break;
    case Unknowns::PoseAndScale: free_ = {0, 1, 2, 3}; break;
    case Unknowns::Orientation: free_ = {2}; break;
  }
  const int d = dim();
  centre_.resize(d), half_.resize(d);
  for (int k = 0; k < d; ++k) {
    const int i = free_[k];
    if (i == 3) {
      if (!(initial[3] >= box.scale_low && initial[3] <= box.scale_high))
        throw std::invalid_argument("initial: the scale " + std::to_string(initial[3]) + " is outside the box [" +
                                    std::to_string(box.scale_low) + ", " + std::to_string(box.scale_high) + "]");
      centre_[k] = 0.5 * (box.scale_low + box.scale_high), half_[k] = 0.5 * (box.scale_high - box.scale_low);
    } else {
      centre_[k] = initial[i], half_[k] = i == 2 ? box.yaw : box.xy;
    }
  }
}

optim::Bounds SearchSpace::unit_bounds() const {
  return optim::Bounds{-Eigen::VectorXd::Ones(dim()), Eigen::VectorXd::Ones(dim())};
}

Eigen::VectorXd SearchSpace::start() const {
  Eigen::VectorXd u(dim());
  for (int k = 0; k < dim(); ++k) u[k] = (initial_[free_[k]] - centre_[k]) / half_[k];
  return u;
}

State SearchSpace::state(const Eigen::VectorXd& u) const {
  State s = initial_;
  for (int k = 0; k < dim(); ++k) s[free_[k]] = centre_[k] + u[k] * half_[k];
  return s;
}

optim::RowMatrixXd SearchSpace::states(const optim::RowMatrixXd& U) const {
  optim::RowMatrixXd S(U.rows(), 4);
  for (int i = 0; i < U.rows(); ++i) S.row(i) = state(U.row(i).transpose()).transpose();
  return S;
}

}  // namespace bayesgrasp::touch
