// Densities over 6-DoF hand poses around a demonstrated grasp: Eq. 4.1's P(A | T_ik, O_i; theta_ik).
//
// For a candidate hand pose A = (R_A, t_A) and a grasp G = (R_G, t_G) in the same frame, with
//   d_t = |t_A - t_G|                      (m)
//   d_R = angle(R_G^T R_A) in [0, pi]      (rad)
// the three forms (unnormalised, 1 at d_t = d_R = 0; the thesis names them, the formulas are ours):
//   Gaussian              g(s_t, s_R) = exp(-(d_t^2 / s_t^2 + d_R^2 / s_R^2) / 2)
//   regularised Gaussian  (1 - lambda) g(s_t, s_R) + lambda g(kappa s_t, kappa s_R)
//                         (a wide component that keeps a gradient far from every grasp, against
//                         the local optima the thesis reports for the plain Gaussian)
//   Laplace               exp(-(d_t / s_t + d_R / s_R))
// with s_t = translation_scale, s_R = rotation_scale, lambda = wide_weight, kappa = wide_factor.
#pragma once

namespace bayesgrasp::task {

enum class DensityKind { Gaussian, RegularisedGaussian, Laplace };

struct PoseDensity {
  DensityKind kind = DensityKind::Laplace;
  double translation_scale = 0.01;               // s_t (m)
  double rotation_scale = 0.17453292519943295;   // s_R (rad), 10 degrees
  double wide_weight = 0.2;                      // lambda, regularised Gaussian only
  double wide_factor = 4.0;                      // kappa, regularised Gaussian only

  /// Throws std::invalid_argument naming the field: scales must be positive and finite,
  /// wide_weight in [0, 1], wide_factor >= 1.
  void validate() const;

  /// The density at translation distance dt (m) and rotation angle dr (rad).
  double operator()(double dt, double dr) const;
};

}  // namespace bayesgrasp::task
