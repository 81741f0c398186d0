// Simulated annealing: a population of independent Metropolis chains (evaluated as one batch
// per iteration) with bounded Gaussian random-walk proposals and geometric cooling.
#pragma once

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::optim {

/// PopulationOptions::init: (n_chains, D) starting points.
struct AnnealingOptions : PopulationOptions {
  int n_chains = 16;
  int max_iter = 1000;        ///< proposals per chain after the initial evaluation
  double t0 = -1.0;           ///< initial temperature; <= 0: the std of f over the initial chains (1 if that is 0)
  double cooling = 0.98;      ///< T_k = t0 * cooling^k, in (0, 1]
  double step = 0.1;          ///< initial proposal std as a fraction of (high - low)
  double step_min = 1e-9;     ///< bounds of the adapted proposal std (fractions of the range)
  double step_max = 0.5;
  /// Each chain adapts its proposal std every adapt_interval iterations (Corana et al. 1987
  /// style): times adapt_factor if its acceptance rate was above target_acceptance, divided
  /// otherwise. This lets the chains refine as the temperature falls. 0 = fixed step.
  int adapt_interval = 10;
  double target_acceptance = 0.2;
  double adapt_factor = 1.5;
};

/// Proposals leaving the box are reflected back into it. Evaluations = n_chains * (iterations + 1).
/// Throws std::invalid_argument naming the first bad field.
void validate(const AnnealingOptions& o);

Result simulated_annealing(const BatchObjective& fun, const Bounds& bounds, const AnnealingOptions& opt = {});

}  // namespace bayesgrasp::optim
