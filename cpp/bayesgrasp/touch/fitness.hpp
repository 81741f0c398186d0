// Pub. I's fitness: how far the readings a candidate object state predicts are from the measured
// ones (the thesis gives its ingredients, contacts and joint angles, but no formula). For
// candidate x with predicted joints q(x), contact flags c(x) and hand height z(x):
//
//   f(x) = sum_j w_j ((q_j(x) - q_j^m) / sigma_q)^2          joint term
//        + lambda_c * C(x)                                   contact term
//        + ((z(x) - z^m) / sigma_z)^2                        hand-height term (top grasps)
//        + collision_penalty [the open hand starts inside the candidate]   (closings)
//
// with the contact term either
//   Flags:   C = sum_l (c_l(x) - c_l^m)^2, the number of links whose flag differs; or
//   Surface: the continuous variant for the flat areas the flags leave, evaluated with the
//            measured closed hand placed at the candidate: for a link that touched,
//            min(1, max(0, d_l - tol) / d_s)^2 (d_l its distance to the candidate's surface, tol
//            the contact tolerance), for a link that did not, 1 if it penetrates the candidate.
//            A link touching a surface 1 cm (d_s) away counts as much as a wrong flag.
//
// Weights (FitnessOptions defaults) and why: the spread is commanded, not sensed (w_0 = 0); every
// phalanx joint counts the same (w_j = 1). sigma_q = 0.05 rad (about 3 degrees): about the change
// of a finger's closing angle when the object moves by a few millimetres, far above the
// simulator's resolution (the contact tolerance over a phalanx length, 0.2 mm / 55 mm = 0.004 rad),
// so that states a few millimetres apart are told apart by the joints alone. lambda_c = 1: one
// wrong contact flag weighs as much as one joint off by sigma_q. sigma_z = 5 mm: a descent
// stopping half a centimetre off weighs as much, too. The true state predicts the measured
// readings up to that resolution, so f(truth) ~ 0 (exactly 0 when the object frame is the world's).
#pragma once

#include "bayesgrasp/touch/touch_model.hpp"

namespace bayesgrasp::touch {

enum class ContactTerm { Flags, Surface };

struct FitnessOptions {
  double joint_sigma = 0.05;        ///< sigma_q (rad), > 0
  Eigen::VectorXd joint_weights;    ///< w_j (J,), >= 0; empty = 0 for the spread, 1 for every phalanx
  ContactTerm contact_term = ContactTerm::Flags;
  double contact_weight = 1.0;      ///< lambda_c, >= 0
  double surface_scale = 0.01;      ///< d_s (m), > 0 (ContactTerm::Surface)
  double height_sigma = 0.005;      ///< sigma_z (m), > 0; only for top grasps
  double collision_penalty = 10.0;  ///< added when the open hand starts inside the candidate, >= 0
};

/// Throws std::invalid_argument naming the option out of range (J: the hand's joints).
/// Throws std::invalid_argument naming the first bad field (joint_weights' length is checked
/// against the hand by check_fitness_options).
void validate(const FitnessOptions& o);
void check_fitness_options(const FitnessOptions& o, int num_joints);

/// The three terms of f per candidate, and their sum.
struct FitnessTerms {
  Eigen::VectorXd joint, contact, height, total;  ///< (N,) each
};

/// f for every candidate of `p` against `measured`; `grasp` says whether the height term applies.
/// ContactTerm::Surface needs predictions made with the measurement (TouchModel::predict with
/// `measured`).
FitnessTerms fitness(const TouchPredictions& p, const TouchReadings& measured, const TouchGrasp& grasp,
                     double contact_tolerance, const FitnessOptions& o);

/// The model's predictions and their fitness in one call: f at each row of `states`.
FitnessTerms evaluate_fitness(const TouchModel& model, const TouchGrasp& grasp, const TouchReadings& measured,
                              const RowMatrixXd& states, const FitnessOptions& o, int threads = 1);

}  // namespace bayesgrasp::touch
