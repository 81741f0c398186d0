// What a touch estimates and where it looks (Pub. I's cases): the object state (x, y, yaw, scale)
// with some of it unknown, searched in a box around the initial guess. The optimisers work in
// unit coordinates u in [-1, 1]^d (one per unknown), so that their steps, finite differences and
// distances do not depend on the units of metres, radians and scale factors.
#pragma once

#include <Eigen/Core>

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::touch {

/// Pub. I's cases: 3 DoF (position and orientation), 4 DoF (plus a uniform scale), and the
/// orientation alone with the position (and scale) given.
enum class Unknowns { Pose, PoseAndScale, Orientation };

/// The search box: the initial guess +- xy (m) in x and y, +- yaw (rad), and the scale range.
struct SearchBox {
  double xy = 0.03;
  double yaw = 30.0 * M_PI / 180.0;
  double scale_low = 0.8, scale_high = 1.2;
};

/// Throws std::invalid_argument naming the field out of range.
void validate(const SearchBox& b);

/// An object state: x, y (m), yaw (rad), scale.
using State = Eigen::Vector4d;

class SearchSpace {
 public:
  /// `initial`: the initial guess (its scale within the box's scale range).
  SearchSpace(Unknowns unknowns, const State& initial, const SearchBox& box);

  int dim() const { return static_cast<int>(free_.size()); }
  Unknowns unknowns() const { return unknowns_; }
  /// [-1, 1]^dim.
  optim::Bounds unit_bounds() const;
  /// The unit coordinates of the initial guess.
  Eigen::VectorXd start() const;
  /// The state at unit coordinates u (dim,).
  State state(const Eigen::VectorXd& u) const;
  /// The states (N, 4) at unit coordinates U (N, dim).
  optim::RowMatrixXd states(const optim::RowMatrixXd& U) const;

 private:
  Unknowns unknowns_;
  State initial_;
  std::vector<int> free_;       // which state entries are unknown
  Eigen::VectorXd centre_, half_;  // of the free entries
};

}  // namespace bayesgrasp::touch
