#include "bayesgrasp/touch/fitness.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::touch {

namespace {

Eigen::VectorXd joint_weights(const FitnessOptions& o, int J) {
  if (o.joint_weights.size() > 0) return o.joint_weights;
  Eigen::VectorXd w = Eigen::VectorXd::Ones(J);
  w[0] = 0.0;  // the spread is commanded
  return w;
}

double positive_term(double v, const char* name) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + ": must be positive and finite, got " + std::to_string(v));
  return v;
}

double nonnegative_term(double v, const char* name) {
  if (!(v >= 0.0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + ": must be >= 0 and finite, got " + std::to_string(v));
  return v;
}

/// The continuous contact term of one candidate (see fitness.hpp).
double surface_term(const TouchPredictions& p, int i, const TouchReadings& m, double tol, double scale) {
  double c = 0.0;
  for (int l = 0; l < p.surface_distance.cols(); ++l) {
    if (m.contact[l]) {
      const double d = p.surface_distance(i, l);  // NaN: a link without shapes; +inf: beyond the cap
      if (std::isnan(d)) continue;
      const double e = std::min(1.0, std::max(0.0, d - tol) / scale);
      c += e * e;
    } else if (p.penetrating(i, l)) {
      c += 1.0;
    }
  }
  return c;
}

}  // namespace

void validate(const FitnessOptions& o) {
  positive_term(o.joint_sigma, "joint_sigma");
  nonnegative_term(o.contact_weight, "contact_weight");
  positive_term(o.surface_scale, "surface_scale");
  positive_term(o.height_sigma, "height_sigma");
  nonnegative_term(o.collision_penalty, "collision_penalty");
  if (!o.joint_weights.allFinite() || (o.joint_weights.array() < 0.0).any())
    throw std::invalid_argument("joint_weights: must be finite and >= 0");
}

void check_fitness_options(const FitnessOptions& o, int J) {
  validate(o);
  if (o.joint_weights.size() == 0) return;
  if (o.joint_weights.size() != J)
    throw std::invalid_argument("joint_weights: expected " + std::to_string(J) + " weights (one per joint), got " +
                                std::to_string(o.joint_weights.size()));
  if (!o.joint_weights.allFinite() || (o.joint_weights.array() < 0.0).any())
    throw std::invalid_argument("joint_weights: must be finite and >= 0");
}

FitnessTerms fitness(const TouchPredictions& p, const TouchReadings& m, const TouchGrasp& grasp, double tol,
                     const FitnessOptions& o) {
  const int N = p.num_candidates, J = static_cast<int>(p.joints.cols()), L = static_cast<int>(p.contact.cols());
  check_fitness_options(o, J);
  if (m.joints.size() != J || static_cast<int>(m.contact.size()) != L)
    throw std::invalid_argument("measured: joints and contact flags do not match the predictions");
  const bool surface = o.contact_term == ContactTerm::Surface;
  if (surface && p.surface_distance.rows() != N)
    throw std::invalid_argument("contact_term: Surface needs predictions made with the measurement");
  const Eigen::VectorXd w = joint_weights(o, J);
  const bool height = grasp.kind == TouchGrasp::Kind::TopGrasp;
  const double zm = m.hand_pose.translation().z();
  FitnessTerms t;
  t.joint.resize(N), t.contact.resize(N), t.height.setZero(N), t.total.resize(N);
  for (int i = 0; i < N; ++i) {
    const Eigen::ArrayXd dq = (p.joints.row(i).transpose() - m.joints).array() / o.joint_sigma;
    t.joint[i] = (w.array() * dq * dq).sum();
    double c = 0.0;
    if (surface) {
      c = surface_term(p, i, m, tol, o.surface_scale);
    } else {
      for (int l = 0; l < L; ++l) c += (p.contact(i, l) != 0) != (m.contact[l] != 0);
    }
    t.contact[i] = o.contact_weight * c;
    if (height) {
      const double dz = (p.hand_height[i] - zm) / o.height_sigma;
      t.height[i] = dz * dz;
    }
    t.total[i] = t.joint[i] + t.contact[i] + t.height[i] + (p.collision_at_start[i] ? o.collision_penalty : 0.0);
  }
  return t;
}

FitnessTerms evaluate_fitness(const TouchModel& model, const TouchGrasp& grasp, const TouchReadings& measured,
                              const RowMatrixXd& states, const FitnessOptions& o, int threads) {
  check_fitness_options(o, model.hand().num_joints());
  const double tol = model.options().sim.contact_tolerance;
  // the surface term saturates at d = tol + surface_scale: farther distances need no exact query
  const TouchPredictions p = o.contact_term == ContactTerm::Surface
                                 ? model.predict(grasp, states, measured, threads, 1.01 * (tol + o.surface_scale))
                                 : (check_readings(model.hand(), measured), model.predict(grasp, states, threads));
  return fitness(p, measured, grasp, tol, o);
}

}  // namespace bayesgrasp::touch
