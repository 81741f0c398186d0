// Bindings for cpp/bayesgrasp/quality: grasp wrench space, Ferrari-Canny epsilon, volume. Thin:
// convert arrays to contacts, release the GIL for the hulls; the core validates the parameters
// and contacts (its std::invalid_argument becomes ValueError).
#include <cstdint>
#include <string>

#include "bayesgrasp/quality/wrench_space.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

QualityParams params(double mu, int n_edges, bool volume) {
  QualityParams p;
  p.mu = mu;
  p.n_edges = n_edges;
  p.volume = volume;
  return p;
}

Vec3 com_arg(const DArray& com) { return vector(com, "com", 3); }

// Contacts from (K, 3) points and normals (rows [begin, end)).
Contacts contacts_from(const RowMatrixXd& P, const RowMatrixXd& N, Eigen::Index begin, Eigen::Index end) {
  Contacts cs;
  cs.reserve(static_cast<size_t>(end - begin));
  for (Eigen::Index i = begin; i < end; ++i) {
    Contact c;
    c.point = P.row(i).transpose();
    c.normal = N.row(i).transpose();
    cs.push_back(c);
  }
  return cs;
}

std::pair<RowMatrixXd, RowMatrixXd> points_normals(const DArray& points, const DArray& normals) {
  RowMatrixXd P = matrix(points, "points", 3, true);
  RowMatrixXd N = matrix(normals, "normals", 3, true);
  if (P.rows() != N.rows())
    throw py::value_error("points and normals: different numbers of rows (" + std::to_string(P.rows()) + " vs " +
                          std::to_string(N.rows()) + ")");
  return {std::move(P), std::move(N)};
}

void bind_contact_wrenches(py::module_& m) {
  m.def(
      "contact_wrenches",
      [](const DArray& points, const DArray& normals, const DArray& com, double torque_scale, double mu, int n_edges) {
        auto [P, N] = points_normals(points, normals);
        const Vec3 c = com_arg(com);
        const Wrenches W = contact_wrenches(contacts_from(P, N, 0, P.rows()), c, torque_scale, params(mu, n_edges, false));
        return to_numpy(W);
      },
      py::arg("points"), py::arg("normals"), py::arg("com"), py::arg("torque_scale"),
      py::arg("mu") = kDefaultFriction, py::arg("n_edges") = kDefaultConeEdges,
      R"doc(Primitive wrenches of point contacts with linearised friction cones.

Args:
    points: (K, 3) contact points on the object (m).
    normals: (K, 3) outward object surface normals (normalised here; non-zero).
    com: (3,) centre of mass.
    torque_scale: > 0, largest distance from the centre of mass to the surface (m).
    mu: friction coefficient >= 0 (0: frictionless, one wrench per contact).
    n_edges: friction-cone edges, >= 3.

Returns:
    (K * n_edges, 6) array (K rows if mu == 0): rows (f, (p - com) x f / torque_scale),
    f = -n + mu (cos a t1 + sin a t2), a = 2 pi j / n_edges (unit normal component).)doc");
}

void bind_epsilon_volume(py::module_& m) {
  m.def(
      "epsilon_volume",
      [](const DArray& points, const DArray& normals, const DArray& com, double torque_scale, double mu, int n_edges,
         bool volume) {
        auto [P, N] = points_normals(points, normals);
        const Vec3 c = com_arg(com);
        const QualityParams p = params(mu, n_edges, volume);
        const Contacts cs = contacts_from(P, N, 0, P.rows());
        GraspQuality q;
        {
          py::gil_scoped_release release;
          q = grasp_quality(cs, c, torque_scale, p);
        }
        return py::make_tuple(q.epsilon, q.volume);
      },
      py::arg("points"), py::arg("normals"), py::arg("com"), py::arg("torque_scale"),
      py::arg("mu") = kDefaultFriction, py::arg("n_edges") = kDefaultConeEdges, py::arg("volume") = true,
      R"doc(Ferrari-Canny epsilon and volume of the L1 grasp wrench space of one grasp.

The GWS is the convex hull of the contact wrenches (see ``contact_wrenches``): the wrenches
the hand can apply with a total normal force of at most 1. epsilon is the radius of the
largest origin-centred ball inside it; without force closure it is <= 0 (0 when the
wrenches do not span 6-D, e.g. fewer than 7 wrenches, 1-2 frictionless contacts, two
antipodal or collinear contacts; otherwise minus the largest facet violation). Never an
error for degenerate grasps.

Args:
    points: (K, 3) contact points on the object (K may be 0).
    normals: (K, 3) outward object surface normals.
    com: (3,) centre of mass.
    torque_scale: > 0, largest distance from the centre of mass to the surface (m).
    mu: friction coefficient >= 0.
    n_edges: friction-cone edges, >= 3.
    volume: also compute the 6-D volume (a share of the cost); else 0.

Returns:
    (epsilon, volume) floats.)doc");
}

// Contacts of N grasps from (M, 3) points and normals and (N,) counts (sum M).
// Counts are read as int64 (a forced int32 cast would truncate 2^32 + 3 to 3) and checked.
using CountArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
std::vector<Contacts> grasps_from(const RowMatrixXd& P, const RowMatrixXd& N, const CountArray& counts) {
  if (counts.ndim() != 1) throw py::value_error("counts: expected shape (N,), got " + shape_str(counts));
  const py::ssize_t n = counts.shape(0);
  std::vector<Contacts> grasps(static_cast<size_t>(n));
  Eigen::Index row = 0;
  for (py::ssize_t i = 0; i < n; ++i) {
    const std::int64_t k = counts.data()[i];
    if (k < 0) throw py::value_error("counts: entry " + std::to_string(i) + " is negative");
    if (row + k > P.rows())
      throw py::value_error("counts: sum exceeds the number of points (" + std::to_string(P.rows()) + ") at entry " +
                            std::to_string(i));
    grasps[static_cast<size_t>(i)] = contacts_from(P, N, row, row + k);
    row += k;
  }
  if (row != P.rows())
    throw py::value_error("counts: sum " + std::to_string(row) + " != number of points " + std::to_string(P.rows()));
  return grasps;
}

void bind_epsilon_volume_batch(py::module_& m) {
  m.def(
      "epsilon_volume_batch",
      [](const DArray& points, const DArray& normals, const CountArray& counts, const DArray& com, double torque_scale,
         double mu, int n_edges, bool volume, int threads) {
        auto [P, N] = points_normals(points, normals);
        const std::vector<Contacts> grasps = grasps_from(P, N, counts);
        const Vec3 c = com_arg(com);
        const QualityParams p = params(mu, n_edges, volume);
        const py::ssize_t n = static_cast<py::ssize_t>(grasps.size());
        std::vector<GraspQuality> q;
        {
          py::gil_scoped_release release;
          q = grasp_quality_batch(grasps, c, torque_scale, p, threads);
        }
        py::array_t<double> eps(n), vol(n);
        for (py::ssize_t i = 0; i < n; ++i) {
          eps.mutable_data()[i] = q[static_cast<size_t>(i)].epsilon;
          vol.mutable_data()[i] = q[static_cast<size_t>(i)].volume;
        }
        return py::make_tuple(eps, vol);
      },
      py::arg("points"), py::arg("normals"), py::arg("counts"), py::arg("com"), py::arg("torque_scale"),
      py::arg("mu") = kDefaultFriction, py::arg("n_edges") = kDefaultConeEdges, py::arg("volume") = true,
      py::arg("threads") = 0,
      R"doc(``epsilon_volume`` for N grasps of the same object, in OpenMP threads (GIL released).

Args:
    points: (M, 3) contact points of all grasps, grasp after grasp.
    normals: (M, 3) outward normals.
    counts: (N,) int, number of contacts of each grasp (sum = M; zeros allowed).
    com, torque_scale, mu, n_edges, volume: as in ``epsilon_volume``.
    threads: OpenMP threads (0 = all cores).

Returns:
    (epsilon (N,), volume (N,)) arrays, equal to the one-by-one results.)doc");
}

}  // namespace

void bind_quality(py::module_& m) {
  m.attr("DEFAULT_FRICTION") = kDefaultFriction;
  m.attr("DEFAULT_CONE_EDGES") = kDefaultConeEdges;
  bind_contact_wrenches(m);
  bind_epsilon_volume(m);
  bind_epsilon_volume_batch(m);
}

}  // namespace bayesgrasp::bind
