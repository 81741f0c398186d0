#include "bayesgrasp/sim/query_pruning.hpp"

#include <algorithm>

#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

bool slivers_only(const std::vector<LinkShape>& shapes) {
  return std::all_of(shapes.begin(), shapes.end(), [](const LinkShape& s) { return s.sliver; });
}

}  // namespace

void evaluate_link(const SimScene& s, int link, const Iso3& T, LinkDistance& c, int& queries, double bound) {
  const SimOptions& o = s.options;
  c.table = o.table ? table_distance(s.links[link], T) : kInf;
  c.current = true;
  c.deferred = false;
  const double bd = std::max(box_distance(s.links[link], T, s.object), bound);
  if (!s.pruning()) {
    advancing_bounds(s, link, T, bd, c.carried_lower, c.lower, c.upper, queries);
    return;
  }
  // The unpruned value is the bound bd when bd > box_skip, else the FCL distance. That FCL
  // distance is at least max(bd, carried_lower); while that bound reaches the contact tolerance
  // the link cannot touch, and the query waits until the step needs it (resolve_deferred).
  if (bd > o.box_skip) {
    c.lower = bd, c.upper = kInf;
  } else if (std::max(bd, c.carried_lower) >= o.contact_tolerance) {
    c.lower = std::max(bd, c.carried_lower), c.upper = kInf, c.deferred = true;
  } else if (slivers_only(s.links[link])) {
    c.lower = c.upper = distance_below(s, link, T, kInf, queries, &c.warm);
  } else {
    // The link may touch. Boxes (and capsules as primitives or meshes) are costly to query near
    // a large surface: a query capped at the tolerance decides the contact (FCL prunes
    // everything farther); a larger distance is at least the tolerance and waits, deferred,
    // until the step needs it.
    const double d = distance_below(s, link, T, o.contact_tolerance, queries, &c.warm);
    if (d < kInf) c.lower = c.upper = d;
    else c.lower = o.contact_tolerance, c.upper = kInf, c.deferred = true;
  }
}

}  // namespace bayesgrasp::sim
