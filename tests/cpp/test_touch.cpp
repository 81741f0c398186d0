// The touch model, fitness and estimate (Pub. I) against derivable oracles: a world simulated in
// the world frame (the object's mesh moved to its pose) against the model's re-simulation in the
// object's frame, symmetric objects, exact identities at the identity pose, bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "bayesgrasp/touch/estimate.hpp"

using namespace bayesgrasp;
using namespace bayesgrasp::touch;

namespace {
const std::string kBarrett = std::string(BAYESGRASP_SOURCE_DIR) + "/python/bayesgrasp/data/hands/barrett_bh8.json";
constexpr double kDeg = M_PI / 180.0;

/// A right prism over a convex polygon (counter-clockwise, around the origin) from z = 0 to h.
TriMesh prism(const std::vector<Eigen::Vector2d>& poly, double h) {
  const int n = static_cast<int>(poly.size());
  TriMesh m;
  m.V.resize(2 * n, 3);
  for (int k = 0; k < 2 * n; ++k) m.V.row(k) << poly[k % n].x(), poly[k % n].y(), k < n ? 0.0 : h;
  m.F.resize(4 * n - 4, 3);
  int f = 0;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.F.row(f++) << i, j, n + j;
    m.F.row(f++) << i, n + j, n + i;
  }
  for (int i = 1; i + 1 < n; ++i) m.F.row(f++) << 0, i + 1, i, m.F.row(f++) << n, n + i, n + i + 1;
  return m;
}

TriMesh square_prism(double half, double h) {
  return prism({{-half, -half}, {half, -half}, {half, half}, {-half, half}}, h);
}

/// A regular n-gon prism (a body of revolution up to its n-fold symmetry).
TriMesh ngon_prism(int n, double r, double h) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(r * std::cos(2 * M_PI * i / n), r * std::sin(2 * M_PI * i / n));
  return prism(p, h);
}

/// An asymmetric box (no yaw symmetry but the 180 degree one: 8 x 5 cm, 7 cm high, off-centre).
TriMesh slab() { return prism({{-0.03, -0.025}, {0.05, -0.025}, {0.05, 0.025}, {-0.03, 0.025}}, 0.07); }

/// The world: the object's mesh moved to its planar pose (and scale) in the world frame.
GraspSimulator world(const HandModel& hand, const TriMesh& object, const State& s) {
  TriMesh m = object;
  m.V *= s[3];
  return GraspSimulator(hand, transformed(m, planar_pose(s[0], s[1], s[2])), SimOptions{});
}

RowMatrixXd rows(std::initializer_list<State> states) {
  RowMatrixXd S(static_cast<int>(states.size()), 4);
  int i = 0;
  for (const State& s : states) S.row(i++) = s.transpose();
  return S;
}

struct Touch {
  HandModel hand = HandModel::from_file(kBarrett);
  TriMesh object;
  State truth;
  TouchGrasp grasp;
  TouchReadings measured;
  Touch(const TriMesh& obj, const State& t, const TouchGrasp& g) : object(obj), truth(t), grasp(g) {
    measured = readings_of(execute(world(hand, object, truth), grasp));
  }
};

}  // namespace

TEST(Touch, IdentityPoseReproducesTheWorldExactly) {
  // At the object frame's own pose and a grasp yaw of 0 the world's mesh and hand pose are the
  // model's (no rotation round-off): the readings agree bit for bit.
  Touch t(slab(), State(0, 0, 0, 1), TouchGrasp::top(0.004, -0.003, 0.0, 0.0));
  const TouchModel model(t.hand, t.object);
  const TouchPredictions p = model.predict(t.grasp, rows({t.truth}));
  EXPECT_EQ(p.joints.row(0).transpose(), t.measured.joints);
  for (int l = 0; l < t.hand.num_links(); ++l) EXPECT_EQ(p.contact(0, l), t.measured.contact[l]);
  EXPECT_EQ(p.hand_height[0], t.measured.hand_pose.translation().z());
  FitnessOptions o;
  EXPECT_EQ(fitness(p, t.measured, t.grasp, model.options().sim.contact_tolerance, o).total[0], 0.0);
}

TEST(Touch, TruthPredictsTheMeasuredReadingsAtAnyPose) {
  // Moving the hand into the object's frame instead of the object into the world: the same grasp
  // up to round-off in the conservative advancement (joint angles within the contact tolerance
  // over a phalanx length, 0.2 mm / 55 mm), the same contact flags, and f(truth) ~ 0.
  for (const TouchGrasp& g : {TouchGrasp::top(0.02, -0.01, 0.5, 0.0), TouchGrasp::top(0.03, 0.0, -0.2, 1.0)}) {
    Touch t(slab(), State(0.05, -0.03, 0.7, 1.0), g);
    const TouchModel model(t.hand, t.object);
    const TouchPredictions p = model.predict(t.grasp, rows({t.truth}), t.measured);
    EXPECT_LT((p.joints.row(0).transpose() - t.measured.joints).cwiseAbs().maxCoeff(), 4e-3);
    for (int l = 0; l < t.hand.num_links(); ++l) EXPECT_EQ(p.contact(0, l), t.measured.contact[l]) << l;
    EXPECT_NEAR(p.hand_height[0], t.measured.hand_pose.translation().z(), 1e-9);
    for (ContactTerm term : {ContactTerm::Flags, ContactTerm::Surface}) {
      FitnessOptions o;
      o.contact_term = term;
      const FitnessTerms f = evaluate_fitness(model, t.grasp, t.measured, rows({t.truth}), o);
      EXPECT_LT(f.total[0], 0.01);
      EXPECT_EQ(f.contact[0], 0.0);
    }
  }
}

TEST(Touch, ClosingAtTheMeasuredHandPoseMatchesTheTopGrasp) {
  // Closing at the pose where the world's top grasp closed gives the top grasp's readings.
  Touch t(slab(), State(-0.02, 0.04, -1.0, 1.0), TouchGrasp::top(-0.02, 0.05, -0.8, 0.0));
  const TouchGrasp closing = TouchGrasp::closing(t.measured.hand_pose, 0.0);
  const TouchModel model(t.hand, t.object);
  const TouchPredictions p = model.predict(closing, rows({t.truth}));
  EXPECT_LT((p.joints.row(0).transpose() - t.measured.joints).cwiseAbs().maxCoeff(), 4e-3);
  EXPECT_FALSE(p.collision_at_start[0]);
  // a candidate inside the open hand: flagged, and the fitness carries the penalty
  const TouchPredictions q = model.predict(closing, rows({State(t.measured.hand_pose.translation().x(),
                                                              t.measured.hand_pose.translation().y(), 0.0, 1.6)}));
  EXPECT_TRUE(q.collision_at_start[0]);
  FitnessOptions o;
  EXPECT_GE(fitness(q, t.measured, closing, 2e-4, o).total[0], o.collision_penalty);
}

TEST(Touch, BatchEqualsOneByOne) {
  Touch t(slab(), State(0.0, 0.0, 0.3, 1.0), TouchGrasp::top(0.01, 0.0, 0.2, 0.0));
  const TouchModel model(t.hand, t.object);
  const RowMatrixXd S = rows({State(0.0, 0.0, 0.3, 1.0), State(0.01, -0.01, 0.1, 1.1), State(-0.02, 0.01, 0.6, 0.9),
                              State(0.005, 0.02, -0.2, 1.0)});
  const TouchPredictions batch = model.predict(t.grasp, S, t.measured, 2);
  for (int i = 0; i < S.rows(); ++i) {
    const TouchPredictions one = model.predict(t.grasp, S.row(i), t.measured, 1);
    EXPECT_EQ(batch.joints.row(i), one.joints.row(0));
    EXPECT_EQ(batch.contact.row(i), one.contact.row(0));
    EXPECT_EQ(batch.hand_height[i], one.hand_height[0]);
    const auto a = batch.surface_distance.row(i).array(), b = one.surface_distance.row(0).array();
    EXPECT_TRUE((a == b || (a.isNaN() && b.isNaN())).all());
    EXPECT_EQ(batch.penetrating.row(i), one.penetrating.row(0));
  }
}

TEST(Touch, ScaledWorldIsPredictedAtItsScaleAndScalesAreQuantised) {
  Touch t(slab(), State(0.0, 0.0, 0.0, 1.1), TouchGrasp::top(0.0, 0.0, 0.0, 0.0));
  const TouchModel model(t.hand, t.object);
  const TouchPredictions p = model.predict(t.grasp, rows({State(0, 0, 0, 1.1), State(0, 0, 0, 1.1 + 0.0024)}));
  EXPECT_LT((p.joints.row(0).transpose() - t.measured.joints).cwiseAbs().maxCoeff(), 4e-3);
  EXPECT_EQ(p.joints.row(0), p.joints.row(1));  // both round to 1.100
  EXPECT_NEAR(p.scales[1], 1.1, 1e-12);
  EXPECT_EQ(model.cached_scales(), 1);  // one simulator, at 1.1
}

TEST(Touch, SymmetricObjectsAreFlatInYaw) {
  // The square prism maps onto itself by 90 degrees, the 24-gon by 15: those yaws fit as well as the truth.
  const std::vector<std::pair<TriMesh, double>> objects = {{square_prism(0.03, 0.06), 90.0},
                                                           {ngon_prism(24, 0.035, 0.1), 15.0}};
  for (const auto& [mesh, period] : objects) {
    Touch t(mesh, State(0.01, 0.0, 0.2, 1.0), TouchGrasp::top(0.0, 0.0, 0.0, 0.0));
    const TouchModel model(t.hand, t.object);
    const RowMatrixXd S =
        rows({t.truth, State(0.01, 0.0, 0.2 + period * kDeg, 1.0), State(0.01, 0.0, 0.2 - 2 * period * kDeg, 1.0)});
    const FitnessTerms f = evaluate_fitness(model, t.grasp, t.measured, S, {});
    for (int i = 0; i < 3; ++i) EXPECT_LT(f.total[i], 0.01) << period << " " << i;
  }
}

TEST(Touch, WrongStatesFitWorseAndTheSurfaceTermIsContinuous) {
  Touch t(slab(), State(0.0, 0.0, 0.4, 1.0), TouchGrasp::top(0.0, 0.0, 0.4, 0.0));
  const TouchModel model(t.hand, t.object);
  FitnessOptions o;
  o.contact_term = ContactTerm::Surface;
  std::vector<double> f;
  for (double dx : {0.0, 0.002, 0.004, 0.008}) {
    f.push_back(evaluate_fitness(model, t.grasp, t.measured, rows({State(dx, 0.0, 0.4, 1.0)}), o).contact[0]);
  }
  EXPECT_EQ(f[0], 0.0);
  // moving the object away from the touching links: their distance grows, and so does the term
  EXPECT_GT(f[3], 0.0);
  EXPECT_LE(f[1], f[2] + 1e-12);
  EXPECT_LE(f[2], f[3] + 1e-12);
}

TEST(Touch, EstimatesNeverFitWorseThanTheGuessAndSpendTheBudget) {
  Touch t(slab(), State(0.01, -0.01, 0.3, 1.0), TouchGrasp::top(0.0, 0.0, 0.5, 0.0));
  const TouchModel model(t.hand, t.object);
  const State guess(0.0, 0.0, 0.5, 1.0);
  for (Optimizer opt : {Optimizer::Descent, Optimizer::Annealing, Optimizer::PSO, Optimizer::Firefly,
                        Optimizer::TrustRegion}) {
    EstimateOptions o;
    o.optimizer = opt;
    o.budget = 200;
    o.seed = 7;
    const EstimateResult r = estimate(model, t.grasp, t.measured, guess, o);
    EXPECT_EQ(r.status, EstimateStatus::Estimated);
    EXPECT_LE(r.fitness, r.initial_fitness);
    EXPECT_LE(r.evaluations, o.budget);
    const int P = population_size(opt, 0);
    if (opt == Optimizer::Descent || opt == Optimizer::TrustRegion) EXPECT_EQ(r.evaluations, o.budget);
    else EXPECT_EQ(r.evaluations, P * (o.budget / P));
    EXPECT_EQ(r.trace_evaluations.back(), r.evaluations);
    for (size_t k = 1; k < r.trace_fitness.size(); ++k) EXPECT_LE(r.trace_fitness[k], r.trace_fitness[k - 1]);
    // the search box: within +-3 cm and +-30 degrees of the guess
    EXPECT_LE(std::abs(r.state[0] - guess[0]), 0.03 + 1e-12);
    EXPECT_LE(std::abs(r.state[2] - guess[2]), 30 * kDeg + 1e-12);
    // the same seed, the same estimate
    EXPECT_EQ(estimate(model, t.grasp, t.measured, guess, o).state, r.state);
  }
}

TEST(Touch, OrientationCaseKeepsThePositionAndScaleCaseFindsTheSize) {
  Touch t(slab(), State(0.01, -0.01, 0.3, 1.12), TouchGrasp::top(0.01, -0.01, 0.45, 0.0));
  const TouchModel model(t.hand, t.object);
  EstimateOptions o;
  o.unknowns = Unknowns::Orientation;
  o.budget = 100;
  const EstimateResult yaw = estimate(model, t.grasp, t.measured, State(0.01, -0.01, 0.45, 1.12), o);
  EXPECT_EQ(yaw.state[0], 0.01);
  EXPECT_EQ(yaw.state[1], -0.01);
  EXPECT_EQ(yaw.state[3], 1.12);
  EXPECT_LT(std::abs(yaw.state[2] - 0.3), 2 * kDeg);
  o.unknowns = Unknowns::PoseAndScale;
  o.budget = 600;
  const EstimateResult four = estimate(model, t.grasp, t.measured, State(0.01, -0.01, 0.45, 1.0), o);
  EXPECT_LT(std::abs(four.state[3] - 1.12), std::abs(1.0 - 1.12));
}

TEST(Touch, BadInput) {
  const HandModel hand = HandModel::from_file(kBarrett);
  const TouchModel model(hand, slab());
  // a touch far from the object: no contact, nothing learnt, the guess kept
  const TouchGrasp far = TouchGrasp::top(0.3, 0.3, 0.0, 0.0);
  const TouchReadings none = readings_of(execute(world(hand, slab(), State(0, 0, 0, 1)), far));
  ASSERT_EQ(none.contact_count(), 0);
  const State guess(0.3, 0.3, 0.0, 1.0);
  const EstimateResult r = estimate(model, far, none, guess, EstimateOptions{});
  EXPECT_EQ(r.status, EstimateStatus::NoContact);
  EXPECT_EQ(r.evaluations, 0);
  EXPECT_EQ(r.state, guess);
  // non-finite readings
  TouchReadings bad = none;
  bad.joints[2] = std::nan("");
  EXPECT_THROW(estimate(model, far, bad, guess, EstimateOptions{}), std::invalid_argument);
  bad = none;
  bad.contact.pop_back();
  EXPECT_THROW(model.predict(far, rows({guess}), bad), std::invalid_argument);
  // a budget below the optimiser's minimum
  EstimateOptions o;
  o.budget = 39;  // PSO: 2 x 20 particles
  try {
    estimate(model, far, none, guess, o);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("budget"), std::string::npos);
  }
  EXPECT_EQ(minimum_budget(Optimizer::Descent, 3), 7);
  // states of the wrong shape, out-of-range scale, bad weights
  EXPECT_THROW(model.predict(far, RowMatrixXd::Zero(2, 2)), std::invalid_argument);
  EXPECT_THROW(model.predict(far, rows({State(0, 0, 0, 100.0)})), std::invalid_argument);
  FitnessOptions f;
  f.joint_sigma = 0.0;
  EXPECT_THROW(evaluate_fitness(model, far, none, rows({guess}), f), std::invalid_argument);
}
