#include "bayesgrasp/touch/touch_model.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bayesgrasp/belief/relative_pose.hpp"
#include "bayesgrasp/sim/distance_queries.hpp"
#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp::touch {

namespace {

/// One candidate's re-simulated readings (and, with a measurement, its surface distances).
struct CandidateReadings {
  GraspResult grasp;
  std::vector<double> distance;
  std::vector<uint8_t> penetrating;
};

/// The executed grasp re-simulated on the candidate object at planar pose o (the simulator holds
/// the object in its own frame): the hand moved into the candidate's frame.
GraspResult resimulate(const GraspSimulator& sim, const TouchGrasp& g, const belief::PlanarFrame& o) {
  if (g.kind == TouchGrasp::Kind::TopGrasp) {
    double lx = 0.0, ly = 0.0;
    o.to_local(g.x, g.y, lx, ly);
    GraspResult r = sim.top_grasp(lx, ly, belief::wrap_angle(g.yaw - o.yaw), g.spread, g.standoff);
    r.hand_pose = planar_pose(o.x, o.y, o.yaw) * r.hand_pose;  // back to the world
    return r;
  }
  const Iso3 To = planar_pose(o.x, o.y, o.yaw);
  GraspResult r = sim.close(To.inverse() * g.hand_pose, g.spread);
  r.hand_pose = g.hand_pose;
  return r;
}

/// Per link, the measured closed hand (placed in the candidate's frame) against the candidate: a
/// link that touched, its distance to the surface (below `cap`, else +inf); one that did not,
/// whether it penetrates.
void surface_distances(const GraspSimulator& sim, const TouchReadings& m, const belief::PlanarFrame& o, double cap,
                       CandidateReadings& out) {
  const sim::SimScene& s = sim.scene();
  const Iso3 H = planar_pose(o.x, o.y, o.yaw).inverse() * m.hand_pose;
  const std::vector<Iso3> poses = s.hand.link_poses(H, m.joints);
  const int L = s.hand.num_links();
  out.distance.assign(L, std::numeric_limits<double>::quiet_NaN());
  out.penetrating.assign(L, 0);
  int queries = 0;
  for (int l = 0; l < L; ++l) {
    if (s.links[l].empty()) continue;
    if (m.contact[l]) {
      out.distance[l] = std::max(0.0, sim::nearest_points(s, l, poses[l], queries, cap).distance);
    } else {
      out.penetrating[l] = sim::penetrates(s, l, poses[l], queries) ? 1 : 0;
    }
  }
}

}  // namespace

void check_states(const RowMatrixXd& states, const char* name) {
  const std::string n(name);
  if (states.cols() != 3 && states.cols() != 4)
    throw std::invalid_argument(n + ": expected 3 columns (x, y, yaw) or 4 (x, y, yaw, scale), got " +
                                std::to_string(states.cols()));
  if (states.rows() < 1) throw std::invalid_argument(n + ": is empty");
  if (!states.allFinite()) throw std::invalid_argument(n + ": contains NaN or infinity");
}

void validate(const TouchModelOptions& o) {
  bayesgrasp::validate(o.sim);
  if (!(o.scale_step > 0.0) || !std::isfinite(o.scale_step))
    throw std::invalid_argument("scale_step: must be positive and finite, got " + std::to_string(o.scale_step));
  if (!(o.scale_min > 0.0) || !(o.scale_max >= o.scale_min) || !std::isfinite(o.scale_max))
    throw std::invalid_argument("scale_min, scale_max: need 0 < scale_min <= scale_max < inf");
}

TouchModel::TouchModel(const HandModel& hand, const TriMesh& object, const TouchModelOptions& options)
    : hand_(hand), object_(object), options_(options) {
  validate_mesh(object_);
  validate(options_);
}

double TouchModel::quantised_scale(double scale) const {
  return std::round(scale / options_.scale_step) * options_.scale_step;
}

std::shared_ptr<const GraspSimulator> TouchModel::simulator(double scale) const {
  if (!(scale >= options_.scale_min && scale <= options_.scale_max))
    throw std::invalid_argument("scale: must lie in [" + std::to_string(options_.scale_min) + ", " +
                                std::to_string(options_.scale_max) + "], got " + std::to_string(scale));
  const long key = std::lround(scale / options_.scale_step);
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = simulators_.find(key);
  if (it != simulators_.end()) return it->second;
  TriMesh m = object_;
  m.V *= key * options_.scale_step;
  auto sim = std::make_shared<const GraspSimulator>(hand_, m, options_.sim);
  simulators_.emplace(key, sim);
  return sim;
}

int TouchModel::cached_scales() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(simulators_.size());
}

TouchPredictions TouchModel::predict(const TouchGrasp& grasp, const RowMatrixXd& states, int threads) const {
  return run(grasp, states, nullptr, threads, 0.0);
}

TouchPredictions TouchModel::predict(const TouchGrasp& grasp, const RowMatrixXd& states,
                                     const TouchReadings& measured, int threads, double surface_cap) const {
  check_readings(hand_, measured);
  if (!(surface_cap > 0.0)) throw std::invalid_argument("surface_cap: must be positive");
  return run(grasp, states, &measured, threads, surface_cap);
}

TouchPredictions TouchModel::run(const TouchGrasp& grasp, const RowMatrixXd& states, const TouchReadings* measured,
                                 int threads, double surface_cap) const {
  check_grasp(hand_, grasp);
  check_states(states);
  const int N = static_cast<int>(states.rows()), J = hand_.num_joints(), L = hand_.num_links();
  // Simulators first (serially, under the cache's lock), then the closings in threads.
  std::vector<std::shared_ptr<const GraspSimulator>> sims(N);
  TouchPredictions p;
  p.num_candidates = N;
  p.scales.resize(N);
  for (int i = 0; i < N; ++i) {
    const double s = states.cols() == 4 ? states(i, 3) : 1.0;
    sims[i] = simulator(s);
    p.scales[i] = quantised_scale(s);
  }
  const std::vector<CandidateReadings> out = parallel_map<CandidateReadings>(N, threads, 1, [&](long i) {
    const belief::PlanarFrame o(states(i, 0), states(i, 1), states(i, 2));
    CandidateReadings c;
    c.grasp = resimulate(*sims[i], grasp, o);
    if (measured) surface_distances(*sims[i], *measured, o, surface_cap, c);
    return c;
  });
  p.joints.resize(N, J);
  p.contact.setZero(N, L);
  p.hand_height.resize(N);
  p.collision_at_start.resize(N);
  if (measured) p.surface_distance.resize(N, L), p.penetrating.setZero(N, L);
  for (int i = 0; i < N; ++i) {
    const GraspResult& r = out[i].grasp;
    p.joints.row(i) = r.joints.transpose();
    for (int l = 0; l < L; ++l) p.contact(i, l) = r.link_contact[l];
    p.hand_height[i] = r.hand_pose.translation().z();
    p.collision_at_start[i] = r.collision_at_start;
    if (!measured) continue;
    for (int l = 0; l < L; ++l) {
      p.surface_distance(i, l) = out[i].distance[l];
      p.penetrating(i, l) = out[i].penetrating[l];
    }
  }
  return p;
}

}  // namespace bayesgrasp::touch
