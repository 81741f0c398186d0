// The Registrar (models prepared once, scenes registered against them), the one-shot
// register_models, and the helpers of the public registration API.
#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <shared_mutex>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/parallel.hpp"
#include "bayesgrasp/vision/pipeline.hpp"

namespace bayesgrasp::vision {

struct Registrar::Impl {
  RegistrationOptions options;
  int threads = 1;  // thread_count(options.threads)
  std::vector<std::unique_ptr<PreparedModel>> models;
  mutable std::shared_mutex mutex;  // add_models (unique) against the readers (shared)

  // Throws unless 0 <= i < models.size(); the caller holds the lock.
  const PreparedModel& model(int i) const {
    const std::size_t n = models.size();
    if (i < 0 || static_cast<std::size_t>(i) >= n)
      throw std::invalid_argument("models: index " + std::to_string(i) + " out of range [0, " + std::to_string(n) +
                                  ")");
    return *models[i];
  }

  std::vector<RegistrationResult> register_scene(const Points& scene, std::uint64_t seed,
                                                 const std::optional<Vec3>& viewpoint,
                                                 const std::vector<int>& which) const;
};

namespace {
OrientedCloud scene_cloud(const Points& scene) {
  OrientedCloud raw = finite_points(scene);
  if (raw.size() == 0)
    throw std::invalid_argument("cloud: has no finite points (" + std::to_string(scene.rows()) + " rows)");
  return raw;
}

// Every model fails alike when the scene has too few points with normals.
std::vector<RegistrationResult> too_few_scene_points(std::size_t n, int points, const RegistrationOptions& o) {
  std::vector<RegistrationResult> results(n);
  for (auto& r : results) {
    r.status = RegistrationStatus::TooFewScenePoints;
    r.reason = "scene has " + std::to_string(points) + " points with normals after downsampling at voxel " +
               std::to_string(o.voxel) + " m; at least " + std::to_string(o.min_scene_points) + " are needed";
    r.scene_points = points;
  }
  return results;
}

// The result of a model that could not be prepared.
RegistrationResult unprepared(const PreparedModel& m, const PreparedScene& scene) {
  RegistrationResult r;
  r.status = m.info.status;
  r.reason = m.info.reason;
  r.scene_points = scene.size();
  r.model_points = m.info.points;
  r.time_features = scene.time;
  return r;
}
}  // namespace

std::vector<RegistrationResult> Registrar::Impl::register_scene(const Points& scene, std::uint64_t seed,
                                                                const std::optional<Vec3>& viewpoint,
                                                                const std::vector<int>& which) const {
  if (viewpoint && !viewpoint->allFinite()) throw std::invalid_argument("viewpoint: must be finite");
  const OrientedCloud raw = scene_cloud(scene);
  const PreparedScene sd = prepare_scene(raw, options, viewpoint, threads);
  if (sd.size() < options.min_scene_points) return too_few_scene_points(which.size(), sd.size(), options);
  std::vector<RegistrationResult> results(which.size());
  const int n = static_cast<int>(which.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count_for(threads, n))
  for (int k = 0; k < n; ++k) {
    const PreparedModel& m = *models[which[k]];
    results[k] = m.info.ok() ? register_prepared(m, sd, options, seed) : unprepared(m, sd);
  }
  return results;
}

Registrar::Registrar(const RegistrationOptions& options) : impl_(std::make_unique<Impl>()) {
  validate(options);
  impl_->options = options;
  impl_->threads = thread_count(options.threads);
}
Registrar::~Registrar() = default;
Registrar::Registrar(Registrar&&) noexcept = default;
Registrar& Registrar::operator=(Registrar&&) noexcept = default;

int Registrar::add_models(const std::vector<ModelCloud>& models) {
  const int n = static_cast<int>(models.size());
  std::vector<std::unique_ptr<PreparedModel>> prepared(n);
  const RegistrationOptions& o = impl_->options;
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count_for(impl_->threads, n))
  for (int i = 0; i < n; ++i) prepared[i] = std::make_unique<PreparedModel>(prepare_model(models[i].surface, o));
  std::unique_lock<std::shared_mutex> lock(impl_->mutex);
  const int first = static_cast<int>(impl_->models.size());
  for (auto& m : prepared) impl_->models.push_back(std::move(m));
  return first;
}

int Registrar::size() const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  return static_cast<int>(impl_->models.size());
}

const RegistrationOptions& Registrar::options() const { return impl_->options; }

PreparedModelInfo Registrar::model_info(int i) const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  return impl_->model(i).info;
}

std::vector<RegistrationResult> Registrar::register_scene(const Points& scene, std::uint64_t seed,
                                                          const std::optional<Vec3>& viewpoint) const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  if (impl_->models.empty()) throw std::invalid_argument("models: the registrar has no models");
  std::vector<int> all(impl_->models.size());
  std::iota(all.begin(), all.end(), 0);
  return impl_->register_scene(scene, seed, viewpoint, all);
}

std::vector<RegistrationResult> Registrar::register_scene(const Points& scene, std::uint64_t seed,
                                                          const std::optional<Vec3>& viewpoint,
                                                          const std::vector<int>& models) const {
  std::shared_lock<std::shared_mutex> lock(impl_->mutex);
  if (models.empty()) throw std::invalid_argument("models: is empty");
  for (int i : models) impl_->model(i);  // range check
  return impl_->register_scene(scene, seed, viewpoint, models);
}

std::vector<RegistrationResult> register_models(const Points& scene, const std::vector<ModelCloud>& models,
                                                const RegistrationOptions& options, std::uint64_t seed,
                                                const std::optional<Vec3>& viewpoint) {
  Registrar reg(options);
  if (models.empty()) throw std::invalid_argument("models: is empty");
  scene_cloud(scene);  // a bad scene fails before the models are prepared
  reg.add_models(models);
  std::vector<RegistrationResult> res = reg.register_scene(scene, seed, viewpoint);
  for (int i = 0; i < reg.size(); ++i) res[i].time_features += reg.model_info(i).time;
  return res;
}

ModelCloud model_from_mesh(const TriMesh& mesh, const RegistrationOptions& options, std::uint64_t seed) {
  validate(options);
  validate_mesh(mesh);
  const double area = surface_area(mesh);
  if (!(area > 0)) throw std::invalid_argument("mesh has no surface area");
  int n = options.model_samples;
  if (n <= 0) {
    const double h = options.voxel / 3.0;
    n = static_cast<int>(std::clamp(area / (h * h), 2000.0, 200000.0));
  }
  return ModelCloud{sample_surface(mesh, n, seed)};
}

double rotation_error(const Mat3& Ra, const Mat3& Rb, const Vec3& axis) {
  // Both must be rotations: R^T R = I and det R = +1 (to 1e-6).
  auto check = [](const Mat3& R, const char* name) {
    if (!R.allFinite() || !(R.transpose() * R).isApprox(Mat3::Identity(), 1e-6) || !(std::abs(R.determinant() - 1.0) < 1e-6))
      throw std::invalid_argument(std::string(name) + ": is not a rotation matrix (R^T R = I, det R = 1)");
  };
  check(Ra, "Ra");
  check(Rb, "Rb");
  if (!axis.allFinite()) throw std::invalid_argument("axis: contains NaN or infinity");
  if (axis.norm() > 0) {
    const Vec3 a = axis.normalized();
    return std::acos(std::clamp((Ra * a).dot(Rb * a), -1.0, 1.0));
  }
  return std::acos(std::clamp(((Ra.transpose() * Rb).trace() - 1.0) / 2.0, -1.0, 1.0));
}

}  // namespace bayesgrasp::vision
