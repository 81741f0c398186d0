#include "bayesgrasp/task/grasp_mixture.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::task {

double rotation_angle(const Mat3& Ra, const Mat3& Rb) {
  // trace(Ra^T Rb) = 1 + 2 cos(angle)
  const double c = 0.5 * ((Ra.array() * Rb.array()).sum() - 1.0);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

GraspMixture::GraspMixture(const std::vector<Iso3>& grasps, const Eigen::VectorXd& weights,
                           const std::vector<int>& models, int num_models)
    : grasps_(grasps), weights_(weights), models_(models), num_models_(num_models) {
  const size_t n = grasps.size();
  if (static_cast<size_t>(weights.size()) != n || models.size() != n)
    throw std::invalid_argument("weights, models: need one per grasp (" + std::to_string(n) + ")");
  if (num_models < 1) throw std::invalid_argument("num_models: must be at least 1");
  for (size_t c = 0; c < n; ++c) {
    if (!grasps[c].matrix().allFinite()) throw std::invalid_argument("grasps: pose " + std::to_string(c) + " is not finite");
    if (!(weights[c] >= 0.0) || !std::isfinite(weights[c]))
      throw std::invalid_argument("weights: must be finite and >= 0 (entry " + std::to_string(c) + ")");
    if (models[c] < 0 || models[c] >= num_models)
      throw std::invalid_argument("models: entry " + std::to_string(c) + " is outside [0, num_models)");
    rotations_.push_back(grasps[c].linear());
    translations_.push_back(grasps[c].translation());
  }
}

double GraspMixture::component_terms(const Iso3& A, const PoseDensity& d, double* per_model, int* dominant) const {
  const Mat3 R = A.linear();
  const Vec3 t = A.translation();
  double total = 0.0, best = 0.0;
  int arg = -1;
  for (int c = 0; c < size(); ++c) {
    if (weights_[c] == 0.0) continue;
    const double v = weights_[c] * d((t - translations_[c]).norm(), rotation_angle(rotations_[c], R));
    total += v;
    if (per_model) per_model[models_[c]] += v;
    if (v > best) best = v, arg = c;
  }
  *dominant = arg;
  return total;
}

MixtureValues GraspMixture::evaluate(const std::vector<Iso3>& candidates, const PoseDensity& density, bool per_model,
                                     int threads) const {
  density.validate();
  const int N = static_cast<int>(candidates.size());
  for (int i = 0; i < N; ++i)
    if (!candidates[i].matrix().allFinite())
      throw std::invalid_argument("candidates: pose " + std::to_string(i) + " is not finite");
  MixtureValues out;
  out.value.setZero(N);
  out.dominant.setConstant(N, -1);
  if (per_model) out.per_model.setZero(N, num_models_);
  const int nt = thread_count_for(threads, N);
#pragma omp parallel for schedule(static) num_threads(nt)
  for (int i = 0; i < N; ++i)
    out.value[i] = component_terms(candidates[i], density, per_model ? out.per_model.row(i).data() : nullptr,
                                   &out.dominant[i]);
  return out;
}

std::vector<Iso3> poses_from_local(const Iso3& reference, const LocalPoses& X) {
  if (!X.allFinite()) throw std::invalid_argument("local poses: contain NaN or infinity");
  std::vector<Iso3> out(static_cast<size_t>(X.rows()));
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Vec3 t = X.row(i).head<3>().transpose(), r = X.row(i).tail<3>().transpose();
    const double angle = r.norm();
    const Mat3 dR = angle > 1e-15 ? Eigen::AngleAxisd(angle, r / angle).toRotationMatrix() : Mat3::Identity();
    Iso3 A = Iso3::Identity();
    A.linear() = dR * reference.linear();
    A.translation() = reference.translation() + t;
    out[static_cast<size_t>(i)] = A;
  }
  return out;
}

}  // namespace bayesgrasp::task
