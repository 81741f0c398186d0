#include "bayesgrasp/quality/wrench_space.hpp"

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <exception>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "bayesgrasp/common/parallel.hpp"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace bayesgrasp {

namespace {

// Qhull writes its error reports to a FILE*. We never want them on the user's terminal:
// a degenerate grasp is an expected outcome, reported as epsilon = volume = 0. One handle
// on /dev/null, opened once (thread-safe static initialisation) and only ever written to
// (stdio streams lock internally), is shared; if it cannot be opened Qhull gets stderr.
FILE* qhull_errfile() {
  static FILE* f = std::fopen("/dev/null", "w");
  return f ? f : stderr;
}

// Tangent direction for the friction-cone linearisation; see the header.
Vec3 tangent_hint(const Vec3& n, const Vec3& p, const Vec3& com, const Vec3& centroid, double scale) {
  const double tol = 1e-9 * scale;
  Vec3 d = p - com;
  Vec3 t = d - d.dot(n) * n;
  if (t.norm() > tol) return t.normalized();
  d = centroid - p;
  t = d - d.dot(n) * n;
  if (t.norm() > tol) return t.normalized();
  Eigen::Index k;
  n.cwiseAbs().minCoeff(&k);
  t = Vec3::Unit(k).cross(n);
  return t.normalized();
}

}  // namespace

void validate_quality_params(const QualityParams& params, const Vec3& com, double torque_scale) {
  if (!std::isfinite(params.mu) || params.mu < 0.0)
    throw std::invalid_argument("mu: must be finite and >= 0, got " + std::to_string(params.mu));
  // The hull of n_edges x contacts 6-D points grows fast: more than 256 edges per cone would
  // take minutes per grasp (the default is 8).
  if (params.n_edges < 3 || params.n_edges > kMaxConeEdges)
    throw std::invalid_argument("n_edges: must be in [3, " + std::to_string(kMaxConeEdges) + "], got " +
                                std::to_string(params.n_edges));
  if (!std::isfinite(torque_scale) || !(torque_scale > 0.0))
    throw std::invalid_argument("torque_scale: must be positive and finite, got " + std::to_string(torque_scale));
  if (!com.allFinite()) throw std::invalid_argument("com: contains NaN or infinity");
}

Wrenches contact_wrenches(const Contacts& contacts, const Vec3& com, double torque_scale,
                          const QualityParams& params) {
  validate_quality_params(params, com, torque_scale);
  int n_obj = 0;
  Vec3 centroid = Vec3::Zero();
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const Contact& c = contacts[i];
    if (c.on_table) continue;
    const std::string row = ": row " + std::to_string(i);
    if (!c.point.allFinite()) throw std::invalid_argument("points" + row + " contains NaN or infinity");
    if (!c.normal.allFinite()) throw std::invalid_argument("normals" + row + " contains NaN or infinity");
    if (c.normal.norm() < 1e-12) throw std::invalid_argument("normals" + row + " is zero");
    centroid += c.point;
    ++n_obj;
  }
  if (n_obj > 0) centroid /= n_obj;
  const bool frictionless = params.mu == 0.0;
  const int per = frictionless ? 1 : params.n_edges;
  Wrenches W(static_cast<Eigen::Index>(n_obj) * per, 6);
  const double inv_scale = 1.0 / torque_scale;
  Eigen::Index row = 0;
  for (const Contact& c : contacts) {
    if (c.on_table) continue;
    const Vec3 n = c.normal.normalized();
    const Vec3 r = (c.point - com) * inv_scale;
    if (frictionless) {
      const Vec3 f = -n;
      W.row(row).head<3>() = f.transpose();
      W.row(row).tail<3>() = r.cross(f).transpose();
      ++row;
      continue;
    }
    const Vec3 t1 = tangent_hint(n, c.point, com, centroid, torque_scale);
    const Vec3 t2 = n.cross(t1);
    for (int j = 0; j < per; ++j) {
      const double a = 2.0 * M_PI * j / per;
      const Vec3 f = -n + params.mu * (std::cos(a) * t1 + std::sin(a) * t2);
      W.row(row).head<3>() = f.transpose();
      W.row(row).tail<3>() = r.cross(f).transpose();
      ++row;
    }
  }
  return W;
}

namespace {

// One Qhull run on the rows of W with the given options. Returns false if Qhull reported an
// error (degenerate input, or a precision error it could not handle with these options).
bool run_qhull(const Wrenches& W, const char* opts, bool want_volume, GraspQuality& q) {
  // Qhull's signature takes non-const coordinates; it does not write them with these
  // options, but it gets a copy anyway.
  Wrenches pts = W;
  // qhT is a large C struct; keep it off the (possibly small) OpenMP thread stacks.
  auto holder = std::make_unique<qhT>();
  qhT* qh = holder.get();
  FILE* err = qhull_errfile();
  qh_zero(qh, err);
  std::string cmd = std::string("qhull ") + opts;
  // qh_new_qhull catches Qhull's own errors (setjmp/longjmp inside) and returns an exit
  // code; no C++ object with a destructor is created between its setjmp and longjmp.
  const int exitcode = qh_new_qhull(qh, 6, static_cast<int>(pts.rows()), pts.data(), False, cmd.data(),
                                    nullptr, err);
  bool ok = false;
  if (exitcode == 0) {
    double eps = std::numeric_limits<double>::infinity();
    facetT* facet;
    int n_facets = 0;
    FORALLfacets {
      // Outward unit normal; points x inside satisfy normal . x + offset <= 0, so the
      // signed distance from the origin to the facet's plane (positive inside) is -offset.
      eps = std::min(eps, -facet->offset);
      ++n_facets;
    }
    if (n_facets > 0 && std::isfinite(eps)) {
      q.epsilon = eps;
      q.volume = 0.0;
      if (want_volume) {
        qh_getarea(qh, qh->facet_list);
        q.volume = qh->totvol;
      }
      q.hull_ok = ok = true;
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  return ok;
}

}  // namespace

GraspQuality hull_quality(const Wrenches& W, const QualityParams& params) {
  GraspQuality q;
  q.n_wrenches = static_cast<int>(W.rows());
  if (W.rows() < 7 || !W.allFinite()) return q;  // a 6-D simplex needs 7 points
  // First without facet merging ("Q0", the faster run in 6-D); if Qhull meets a precision
  // problem it cannot resolve that way (nearly coplanar wrenches, common for symmetric
  // grasps), again with its default merging and triangulated output ("Qt"). Input that
  // does not span 6-D fails both: epsilon = volume = 0.
  if (run_qhull(W, "Q0", params.volume, q) || run_qhull(W, "Qt", params.volume, q)) return q;
  q.epsilon = 0.0;
  q.volume = 0.0;
  q.hull_ok = false;
  return q;
}

GraspQuality grasp_quality(const Contacts& contacts, const Vec3& com, double torque_scale,
                           const QualityParams& params) {
  const Wrenches W = contact_wrenches(contacts, com, torque_scale, params);
  GraspQuality q = hull_quality(W, params);
  int n_obj = 0;
  for (const Contact& c : contacts) n_obj += c.on_table ? 0 : 1;
  q.n_contacts = n_obj;
  return q;
}

std::vector<GraspQuality> grasp_quality_batch(const std::vector<Contacts>& grasps, const Vec3& com,
                                              double torque_scale, const QualityParams& params,
                                              int n_threads) {
  validate_quality_params(params, com, torque_scale);
  return parallel_map<GraspQuality>(static_cast<long>(grasps.size()), n_threads, 4,
                                     [&](long i) { return grasp_quality(grasps[i], com, torque_scale, params); });
}

}  // namespace bayesgrasp
