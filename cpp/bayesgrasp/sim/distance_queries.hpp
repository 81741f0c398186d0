// FCL queries between one link and the object.
//
// Exact queries give the distance and the nearest points; capped queries (`cap`) only look
// for distances below the cap: FCL prunes every bounding-volume pair no nearer than its best
// distance so far, so starting that best at the cap prunes more without changing the order of
// the traversal (when the distance is below the cap, the same triangle pair and nearest points
// are found as without it). Warm starts begin each shape's search at the distance of the
// triangle pair that was nearest in the link's last query, which prunes from the start.
#pragma once

#include "bayesgrasp/sim/sim_scene.hpp"

namespace bayesgrasp::sim {

/// Distance and nearest points from a link to the object.
struct NearestPoints {
  double distance = kInf;      // negative when penetrating
  Vec3 object_point = Vec3::Zero();
  Vec3 link_point = Vec3::Zero();  // on the link's surface (capsule radius included)
  int triangle = -1;           // the object's nearest triangle
};

/// Per shape (the first kWarmShapes of a link), the nearest (object, link-mesh) triangle pair
/// of the link's last query; -1 before the first.
constexpr int kWarmShapes = 2;
struct WarmStart {
  int pair[kWarmShapes][2] = {{-1, -1}, {-1, -1}};
};

/// Exact distance (FCL) from link `link` at T to the object, with the nearest points. With a
/// finite `cap`, distance = kInf (and triangle = -1) when the distance is not below the cap.
NearestPoints nearest_points(const SimScene& s, int link, const Iso3& T, int& queries, double cap = kInf);

/// Distance from the link to the object if below `cap`, else kInf (no nearest points). With
/// `warm`, each shape's search starts from its last nearest triangle pair (the distance is the
/// same minimum over triangle pairs) and the pair found is recorded.
double distance_below(const SimScene& s, int link, const Iso3& T, double cap, int& queries,
                      WarmStart* warm = nullptr);

/// Bounds on the link-object distance for an advancement step without query pruning: lower
/// (for the step) and upper (for the contact decision). The lower bound `bd` (box_distance or
/// better) replaces FCL when it exceeds box_skip; else FCL with the absolute error allowance
/// rel_err * (a lower bound on the distance: bd or `carried_lower`), so that the true distance
/// is at least the result minus the allowance.
void advancing_bounds(const SimScene& s, int link, const Iso3& T, double bd, double carried_lower, double& lower,
                      double& upper, int& queries);

/// The object's outward normal at a contact: the direction from the object's nearest point to
/// the link's when they are apart (at an edge or a rim the nearest triangle's face normal can
/// be that of the wrong face: a palm resting on a cylinder's top face would get the side
/// wall's horizontal normal at the rim), else the face normal.
Vec3 contact_normal(const SimScene& s, const NearestPoints& e);

/// Whether the link at T penetrates the table or the object (a surface crossing, or lying
/// inside it as judged from the nearest triangle's outward normal).
bool penetrates(const SimScene& s, int link, const Iso3& T, int& queries);

/// Boolean collision check of the link's primitives with the object (the fixed-step reference).
bool collides(const SimScene& s, int link, const Iso3& T, int& queries);

/// For a sliding link: blocked when it comes within `margin` of the object (a distance query:
/// FCL's boolean capsule-mesh check can miss grazing overlaps of a few micrometres that its
/// distance query reports) or reaches the table.
bool sliding_blocked(const SimScene& s, int link, const Iso3& T, double margin, int& queries);

}  // namespace bayesgrasp::sim
