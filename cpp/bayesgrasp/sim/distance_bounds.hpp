// Closed-form distances and lower bounds that spare FCL queries: a link's distance to the
// table (exact: the lowest point of its capsules and boxes), and a lower bound on its distance
// to the object, the larger of the gap between the link's and the object's axis-aligned boxes
// and the separating-axis bound over the object's 26-DOP.
#pragma once

#include <vector>

#include "bayesgrasp/sim/link_geometry.hpp"

namespace bayesgrasp::sim {

/// Height above the table plane z = 0 of the link's lowest point (kInf without shapes).
double table_distance(const std::vector<LinkShape>& shapes, const Iso3& T);

/// The link's lowest point (world); the middle of a horizontal capsule axis.
Vec3 lowest_point(const std::vector<LinkShape>& shapes, const Iso3& T);

/// The lowest point projected onto the table: where a table contact is reported.
inline Vec3 table_point(const std::vector<LinkShape>& shapes, const Iso3& T) {
  Vec3 p = lowest_point(shapes, T);
  p.z() = 0.0;
  return p;
}

/// Lower bound on the distance from the link at T to the object (box gap, 26-DOP).
double box_distance(const std::vector<LinkShape>& shapes, const Iso3& T, const ObjectGeometry& object);

/// The smallest coordinate along unit n of the link's points at T.
double link_min_along(const std::vector<LinkShape>& shapes, const Iso3& T, const Vec3& n);

}  // namespace bayesgrasp::sim
