#include "bayesgrasp/touch/estimate.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <stdexcept>

#include "bayesgrasp/common/parallel.hpp"
#include "bayesgrasp/common/random.hpp"
#include "bayesgrasp/optim/annealing.hpp"
#include "bayesgrasp/optim/firefly.hpp"
#include "bayesgrasp/optim/pso.hpp"
#include "bayesgrasp/optim/trust_region.hpp"
#include "bayesgrasp/touch/budget.hpp"

namespace bayesgrasp::touch {

namespace {

constexpr double kStep = 0.03;  // finite-difference step of the local optimisers (unit coordinates)

bool is_local(Optimizer o) { return o == Optimizer::Descent || o == Optimizer::TrustRegion; }

const char* optimizer_name(Optimizer o) {
  switch (o) {
    case Optimizer::Descent: return "descent";
    case Optimizer::Annealing: return "annealing";
    case Optimizer::PSO: return "pso";
    case Optimizer::Firefly: return "firefly";
    case Optimizer::TrustRegion: return "trust_region";
  }
  return "?";
}

/// A uniform point of [-1, 1]^d.
Eigen::VectorXd uniform_point(Rng& rng, int d) {
  Eigen::VectorXd u(d);
  for (int k = 0; k < d; ++k) u[k] = 2.0 * uniform01(rng) - 1.0;
  return u;
}

/// The initial population: the initial guess and P - 1 uniform points.
optim::RowMatrixXd initial_population(const SearchSpace& space, int P, Rng& rng) {
  optim::RowMatrixXd X(P, space.dim());
  X.row(0) = space.start().transpose();
  for (int i = 1; i < P; ++i) X.row(i) = uniform_point(rng, space.dim()).transpose();
  return X;
}

/// One population optimiser's run: P candidates from `init`, `iterations` iterations.
void run_optimizer(Optimizer which, const optim::BatchObjective& f, const optim::Bounds& box, int P, int iterations,
                   std::uint64_t seed, const optim::RowMatrixXd& init) {
  auto fill = [&](optim::PopulationOptions& o) {
    o.seed = seed;
    o.init = init;
  };
  if (which == Optimizer::PSO) {
    optim::PSOOptions o;
    fill(o);
    o.n_particles = P, o.max_iter = iterations;
    optim::pso(f, box, o);
  } else if (which == Optimizer::Firefly) {
    optim::FireflyOptions o;
    fill(o);
    o.n_fireflies = P, o.max_iter = iterations;
    optim::firefly(f, box, o);
  } else {
    optim::AnnealingOptions o;
    fill(o);
    o.n_chains = P, o.max_iter = iterations;
    optim::simulated_annealing(f, box, o);
  }
}

/// A population optimiser with P candidates for floor(B / P) - 1 iterations, or until the budget's
/// stop level is reached.
void run_population(Optimizer which, BudgetedObjective& budget, const SearchSpace& space, int P, long long B,
                    std::uint64_t seed, Rng& rng) {
  const optim::RowMatrixXd init = initial_population(space, P, rng);
  try {
    run_optimizer(which, budget.objective(), space.unit_bounds(), P, static_cast<int>(B / P) - 1, seed, init);
  } catch (const BudgetExhausted&) {  // stopped below EstimateOptions::stop_fitness
  }
}

/// A local optimiser from the initial guess, restarted from uniform points until the budget is used.
int run_local(Optimizer which, BudgetedObjective& budget, const SearchSpace& space, Rng& rng) {
  const optim::Bounds box = space.unit_bounds();
  const optim::BatchObjective f = budget.objective();
  Eigen::VectorXd u = space.start();
  int restarts = -1;
  try {
    for (;;) {
      ++restarts;
      if (which == Optimizer::Descent) {
        optim::DescentOptions o;
        o.h = kStep, o.t0 = 0.5, o.max_iter = 1000;
        optim::steepest_descent(f, u, box, o);
      } else {
        optim::TrustRegionOptions o;
        o.h = kStep, o.radius0 = 0.3, o.max_radius = 2.0, o.max_iter = 1000;
        optim::trust_region(f, u, box, o);
      }
      u = uniform_point(rng, space.dim());
    }
  } catch (const BudgetExhausted&) {
  }
  return restarts;
}

void check_options(const EstimateOptions& o, int dim) {
  validate(o);
  if (o.population == 1 && !is_local(o.optimizer))
    throw std::invalid_argument("population: a population optimiser needs at least 2 candidates");
  const long long min = minimum_budget(o.optimizer, dim, o.population);
  if (o.budget < min)
    throw std::invalid_argument("budget: " + std::string(optimizer_name(o.optimizer)) + " needs at least " +
                                std::to_string(min) + " evaluations for " + std::to_string(dim) +
                                " unknowns, got " + std::to_string(o.budget));
}

}  // namespace

void validate(const EstimateOptions& o) {
  if (o.population < 0) throw std::invalid_argument("population: must be >= 0 (0 = the default)");
  if (o.budget < 1) throw std::invalid_argument("budget: must be >= 1, got " + std::to_string(o.budget));
  if (!(o.stop_fitness >= 0.0) || !std::isfinite(o.stop_fitness))
    throw std::invalid_argument("stop_fitness: must be >= 0 and finite (0 = spend the whole budget), got " +
                                std::to_string(o.stop_fitness));
  thread_count(o.threads, "threads");
  validate(o.box);
  validate(o.fitness);
}

int population_size(Optimizer optimizer, int requested) {
  if (requested > 0) return requested;
  return optimizer == Optimizer::Annealing ? 10 : 20;
}

long long minimum_budget(Optimizer optimizer, int dim, int population) {
  if (is_local(optimizer)) return 1 + 2LL * dim;
  return 2LL * population_size(optimizer, population);
}

EstimateResult estimate(const TouchModel& model, const TouchGrasp& grasp, const TouchReadings& measured,
                        const State& initial, const EstimateOptions& options) {
  check_grasp(model.hand(), grasp);
  check_readings(model.hand(), measured);
  check_fitness_options(options.fitness, model.hand().num_joints());
  const SearchSpace space(options.unknowns, initial, options.box);
  check_options(options, space.dim());
  EstimateResult r;
  r.initial = r.state = initial;
  auto fitness_at = [&](const optim::RowMatrixXd& S) {
    return evaluate_fitness(model, grasp, measured, S, options.fitness, options.threads);
  };
  optim::RowMatrixXd S0(1, 4);
  S0.row(0) = initial.transpose();
  const FitnessTerms t0 = fitness_at(S0);
  r.initial_fitness = r.fitness = t0.total[0];
  r.joint_term = t0.joint[0], r.contact_term = t0.contact[0], r.height_term = t0.height[0];
  if (measured.contact_count() == 0) {
    r.status = EstimateStatus::NoContact;
    r.message = "the touch made no contact with the object: nothing learnt, the initial guess is kept";
    return r;
  }
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  BudgetedObjective budget(
      [&](const optim::RowMatrixXd& U, Eigen::VectorXd& f) { f = fitness_at(space.states(U)).total; },
      options.budget, options.stop_fitness);
  Rng rng(mix_seed(options.seed));
  if (is_local(options.optimizer)) {
    r.restarts = run_local(options.optimizer, budget, space, rng);
  } else {
    run_population(options.optimizer, budget, space, population_size(options.optimizer, options.population),
                   options.budget, options.seed, rng);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  r.evaluations = budget.used();
  r.stopped = budget.stopped();
  r.trace_evaluations = budget.trace_evaluations();
  r.trace_fitness = budget.trace_best();
  r.message = std::string(optimizer_name(options.optimizer)) + ": " + std::to_string(r.evaluations) + " evaluations";
  if (budget.best_x().size() > 0 && budget.best_f() < r.initial_fitness) {
    r.state = space.state(budget.best_x());
    S0.row(0) = r.state.transpose();
    const FitnessTerms t = fitness_at(S0);
    r.fitness = t.total[0], r.joint_term = t.joint[0], r.contact_term = t.contact[0], r.height_term = t.height[0];
  }
  return r;
}

}  // namespace bayesgrasp::touch
