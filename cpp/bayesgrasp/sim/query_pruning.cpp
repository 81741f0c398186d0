#include "bayesgrasp/sim/query_pruning.hpp"

#include <algorithm>

#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

void evaluate_link(const SimScene& s, int link, const Iso3& T, LinkDistance& c, int& queries) {
  const SimOptions& o = s.options;
  c.table = o.table ? table_distance(s.links[link], T) : kInf;
  c.current = true;
  c.deferred = false;
  if (!s.pruning()) {
    advancing_bounds(s, link, T, c.carried_lower, c.lower, c.upper, queries);
    return;
  }
  // The unpruned value is the box bound bd when bd > box_skip, else the FCL distance. That
  // FCL distance is at least max(bd, carried_lower); while that bound reaches the contact
  // tolerance the link cannot touch, and the query waits until the step needs it
  // (resolve_deferred).
  const double bd = box_distance(s.links[link], T, s.object);
  if (bd > o.box_skip) {
    c.lower = bd, c.upper = kInf;
  } else if (std::max(bd, c.carried_lower) >= o.contact_tolerance) {
    c.lower = std::max(bd, c.carried_lower), c.upper = kInf, c.deferred = true;
  } else {
    c.lower = c.upper = distance_below(s, link, T, kInf, queries, &c.warm);
  }
}

}  // namespace bayesgrasp::sim
