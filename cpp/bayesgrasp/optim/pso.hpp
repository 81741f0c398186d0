// Particle swarm optimisation (global-best topology) with the constriction-equivalent
// parameters of Clerc & Kennedy (2002): inertia 0.7298, c1 = c2 = 1.49618.
#pragma once

#include "bayesgrasp/optim/objective.hpp"

namespace bayesgrasp::optim {

/// PopulationOptions::init: (n_particles, D) initial positions.
struct PSOOptions : PopulationOptions {
  int n_particles = 40;
  int max_iter = 200;              ///< swarm updates after the initial evaluation
  double inertia = 0.7298;
  double c1 = 1.49618;             ///< cognitive (own best) weight
  double c2 = 1.49618;             ///< social (swarm best) weight
  double vmax_fraction = 0.5;      ///< |v_d| <= vmax_fraction * (high_d - low_d)
  int stall_iter = 0;              ///< stop after this many iterations without improvement > ftol (0: off)
  double ftol = 0.0;
};

/// Throws std::invalid_argument naming the first bad field.
void validate(const PSOOptions& o);

/// Minimises fun over the box. Evaluations = n_particles * (iterations + 1).
/// Positions leaving the box are clipped to it and that velocity component set to zero.
Result pso(const BatchObjective& fun, const Bounds& bounds, const PSOOptions& opt = {});

}  // namespace bayesgrasp::optim
