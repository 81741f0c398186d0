// The firefly algorithm (Yang 2008): firefly i moves towards every brighter firefly j by
// beta0 * exp(-gamma r_ij^2) (x_j - x_i) plus a uniform random step alpha (u - 1/2); alpha decays
// geometrically. Distances and steps are measured in the unit box (each dimension scaled by its
// range), so gamma and alpha do not depend on the units of the problem.
#pragma once

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::optim {

/// PopulationOptions::init: (n_fireflies, D) starting points.
struct FireflyOptions : PopulationOptions {
  int n_fireflies = 25;
  int max_iter = 100;          ///< generations after the initial evaluation
  double beta0 = 1.0;          ///< attractiveness at distance 0
  double gamma = 1.0;          ///< light absorption (unit-box coordinates)
  double alpha = 0.2;          ///< initial randomisation (fraction of the range)
  double alpha_decay = 0.97;   ///< alpha_k = alpha * alpha_decay^k
};

/// Moves are synchronous: brightness from the start of a generation, the whole population
/// evaluated as one batch after all moves. Positions are clipped to the box.
/// Evaluations = n_fireflies * (iterations + 1).
/// Throws std::invalid_argument naming the first bad field.
void validate(const FireflyOptions& o);

Result firefly(const BatchObjective& fun, const Bounds& bounds, const FireflyOptions& opt = {});

}  // namespace bayesgrasp::optim
