// One touch's estimate (Pub. I): the object state whose re-simulated grasp best reproduces the
// measured readings, argmin_x f(x) over the search box (touch/fitness.hpp, touch/search_space.hpp),
// found by one of the optimisers the thesis compares (steepest descent, simulated annealing, PSO,
// firefly; a dogleg trust region as a fifth) from optim/, all with the same evaluation budget and
// seed. The objective is evaluated in C++ in batches (a swarm, a stencil, a line-search trial).
//
// How each optimiser spends the budget B (population sizes P from EstimateOptions::population,
// default 20 for PSO and firefly, 10 chains for annealing):
//  * PSO, firefly, annealing: P candidates, floor(B / P) - 1 iterations after the initial
//    population; the initial population holds the initial guess and P - 1 uniform points.
//  * steepest descent, trust region: from the initial guess, then restarted from uniform points
//    of the box whenever a run converges, until the budget is used; finite differences of 0.03
//    in unit coordinates (0.9 mm, 0.9 degrees, a scale step of 0.006 with the default box).
// The result is the best candidate any evaluation saw. With stop_fitness s > 0 the search ends at the
// first batch after which some candidate has f < s (the readings reproduced to that level), so an
// estimate may use fewer evaluations than its budget; s = 0 (the default) always spends it all.
#pragma once

#include <cstdint>
#include <string>

#include "bayesgrasp/touch/fitness.hpp"
#include "bayesgrasp/touch/search_space.hpp"

namespace bayesgrasp::touch {

enum class Optimizer { Descent, Annealing, PSO, Firefly, TrustRegion };

struct EstimateOptions {
  Optimizer optimizer = Optimizer::PSO;
  Unknowns unknowns = Unknowns::Pose;
  SearchBox box;
  FitnessOptions fitness;
  long long budget = 2000;   ///< fitness evaluations (re-simulated closings), >= minimum_budget
  int population = 0;        ///< PSO particles / fireflies / annealing chains; 0 = the default
  std::uint64_t seed = 0;
  int threads = 1;           ///< for the batches (common/parallel.hpp: 0 = all cores)
  double stop_fitness = 0.0; ///< end the search once the best f is below this; 0 = spend the budget
};

/// Throws std::invalid_argument naming the first bad field (its box and fitness too); the budget's
/// minimum for the unknowns is checked by estimate().
void validate(const EstimateOptions& options);

enum class EstimateStatus {
  Estimated,  ///< the optimiser ran
  NoContact,  ///< the touch made no contact with the object: nothing learnt, the guess is kept
};

struct EstimateResult {
  EstimateStatus status = EstimateStatus::Estimated;
  std::string message;
  State initial = State::Zero();   ///< (x, y, yaw, scale)
  State state = State::Zero();     ///< the estimate
  double initial_fitness = 0.0;    ///< f at the initial guess (not counted in evaluations)
  double fitness = 0.0;            ///< f at the estimate
  double joint_term = 0.0, contact_term = 0.0, height_term = 0.0;  ///< its terms
  long long evaluations = 0;       ///< fitness evaluations spent
  bool stopped = false;            ///< the search ended below stop_fitness, before its budget
  int restarts = 0;                ///< local optimisers: runs after the first
  std::vector<long long> trace_evaluations;  ///< after each batch: evaluations so far
  std::vector<double> trace_fitness;         ///< ... and the best f so far
  double seconds = 0.0;            ///< wall time of the search
  double cpu_seconds = 0.0;        ///< processor time of the search (all threads)
};

/// The population size used for `optimizer` (0 = its default).
int population_size(Optimizer optimizer, int requested);

/// The smallest budget `optimizer` can run with in `dim` unknowns: two populations for the
/// population methods, the start and one central-difference gradient (1 + 2 dim) for the local ones.
long long minimum_budget(Optimizer optimizer, int dim, int population = 0);

/// Estimates the object state from one touch. `initial`: the initial guess (x, y, yaw, scale).
/// Throws std::invalid_argument (naming the argument) for bad readings or options, or a budget
/// below minimum_budget. A touch without object contact returns status NoContact.
EstimateResult estimate(const TouchModel& model, const TouchGrasp& grasp, const TouchReadings& measured,
                        const State& initial, const EstimateOptions& options);

}  // namespace bayesgrasp::touch
