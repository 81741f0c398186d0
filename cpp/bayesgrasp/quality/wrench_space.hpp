// Grasp wrench space (GWS) and the two classic quality measures on it: the Ferrari-Canny
// epsilon and the GWS volume (Ferrari & Canny 1992; Miller & Allen 1999, as in GraspIt!).
//
// Model (the L1 GWS, "union of contact wrenches"):
//  * Point contacts with Coulomb friction. Each object contact i (point p_i, outward object
//    normal n_i) has its friction cone linearised into `n_edges` forces around the inward
//    normal -n_i:
//        f_ij = -n_i + mu (cos(2 pi j / n) t1_i + sin(2 pi j / n) t2_i),  j = 0..n-1,
//    i.e. every edge has a UNIT NORMAL COMPONENT (its length is sqrt(1 + mu^2)). With mu = 0
//    the contact is frictionless and contributes the single wrench of f = -n_i.
//  * Wrench of an edge: w_ij = (f_ij, (p_i - com) x f_ij / torque_scale), where torque_scale
//    is the largest distance from the centre of mass to the object's surface, so that
//    forces and torques are commensurate and the measures do not depend on the object's size.
//  * GWS = conv{w_ij}: the wrenches the hand can apply when the SUM of the contacts' normal
//    force magnitudes is at most 1 (the L1 bound).
//  * epsilon = radius of the largest ball centred at the origin inside the GWS
//    = min over hull facets of the distance from the origin to the facet's hyperplane.
//    If the origin is not strictly inside (no force closure), epsilon <= 0: we return
//    min_f (-offset_f), i.e. minus the largest violation of a facet inequality, which is 0
//    when the origin lies on the boundary and negative outside. If the wrenches do not span
//    6-D (fewer than 7 affinely independent wrenches, collinear or coplanar contacts, ...),
//    the GWS has no interior: epsilon = 0 and volume = 0. Never an error.
//  * volume = the 6-D volume of the GWS (units: (1 N)^6 with the normalisation above).
//
// Tangent basis t1_i, t2_i (which only matters for the linearisation, n_edges finite):
// t1_i is the component of (p_i - com) tangent to the surface; if that is ~0 (the normal
// line passes through the centre of mass) it is the tangent component of (centroid of the
// grasp's contacts - p_i); if that is ~0 too, a world axis (the one least aligned with n_i)
// is used. t2_i = n_i x t1_i. The first two rules rotate with the grasp, so the measures
// are exactly invariant to rigid motions of the whole grasp (object, contacts and centre
// of mass together) unless the last rule is reached.
//
// Convex hulls by Qhull (reentrant libqhull_r: first "Q0", no merging, the faster run in
// 6-D; if that meets a precision error, again with default merging, "Qt"), one local qhT
// per call and no global state: every function here is thread-safe.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/geometry/contact.hpp"
#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp {

/// Friction coefficient used when none is given (rubber-coated fingers on plastic or
/// ceramic are around 0.5; GraspIt! uses 0.5 for rubber-plastic as well).
constexpr double kDefaultFriction = 0.5;
/// Default number of edges of the linearised friction cone.
constexpr int kDefaultConeEdges = 8;
constexpr int kMaxConeEdges = 256;  // upper bound on n_edges (validate_quality_params)

/// One row per wrench: (fx, fy, fz, tx, ty, tz), torques already divided by torque_scale.
using Wrenches = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

struct QualityParams {
  double mu = kDefaultFriction;   // Coulomb friction coefficient, >= 0
  int n_edges = kDefaultConeEdges;  // friction-cone edges, >= 3 (ignored when mu == 0)
  bool volume = true;  // compute the GWS volume (a share of the cost, BENCHMARKS.md); else volume = 0
};

struct GraspQuality {
  double epsilon = 0.0;  // Ferrari-Canny epsilon (L1 GWS); <= 0 without force closure
  double volume = 0.0;   // 6-D volume of the GWS; 0 if the wrenches do not span 6-D
  int n_contacts = 0;    // object contacts used (table contacts are ignored)
  int n_wrenches = 0;    // hull input points
  bool hull_ok = false;  // false if Qhull found the wrenches degenerate (lower-dimensional)
};

/// Throws std::invalid_argument for mu < 0 or non-finite, n_edges < 3, torque_scale <= 0
/// or non-finite, or a non-finite com.
void validate_quality_params(const QualityParams& params, const Vec3& com, double torque_scale);

/// The primitive wrenches of the object contacts (table contacts skipped): n_edges rows per
/// contact (one row per contact when mu == 0), contact by contact. Contact normals are
/// normalised here; a contact with a zero or non-finite point/normal throws
/// std::invalid_argument naming its row ("normals: row i is zero").
Wrenches contact_wrenches(const Contacts& contacts, const Vec3& com, double torque_scale,
                          const QualityParams& params = {});

/// Epsilon and (if params.volume) volume of conv(rows of W). Degenerate input (fewer than 7
/// rows, rows not spanning 6-D, Qhull precision failure) gives epsilon = 0, volume = 0,
/// hull_ok = false.
GraspQuality hull_quality(const Wrenches& W, const QualityParams& params = {});

/// contact_wrenches + hull_quality.
GraspQuality grasp_quality(const Contacts& contacts, const Vec3& com, double torque_scale,
                           const QualityParams& params = {});

/// grasp_quality for many grasps of the same object, in n_threads OpenMP threads (0 = all
/// cores, common/parallel.hpp; negative throws). The result equals the serial one element by
/// element.
std::vector<GraspQuality> grasp_quality_batch(const std::vector<Contacts>& grasps, const Vec3& com,
                                              double torque_scale, const QualityParams& params = {},
                                              int n_threads = 0);

}  // namespace bayesgrasp
