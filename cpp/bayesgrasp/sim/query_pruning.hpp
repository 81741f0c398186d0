// Query pruning (SimOptions::prune_queries).
//
// Almost all the time goes to FCL distance queries, and most of them only confirm that a link
// is not the one limiting the step. Every link keeps a lower bound on its object distance,
// carried between steps (its last distance minus the most it can have moved since). A step is
// the minimum over the links' terms; a link whose bound already gives a term no smaller than
// the others' is not queried (its query is deferred), and a link that is queried gets a capped
// query (FCL searches only below the distance that would change the minimum). Links that may
// touch (bound below the tolerance) and the final contact queries (capped at the tolerance)
// are always queried; a link with a box (or a capsule not represented by its axis) first by a
// query capped at the tolerance, as an uncapped query of a box next to a large surface
// traverses most of the object's tree: a larger distance waits, deferred. The steps, contact
// decisions and contacts are therefore those of the unpruned algorithm, up to round-off.
#pragma once

#include <cstdint>

#include "bayesgrasp/sim/distance_queries.hpp"

namespace bayesgrasp::sim {

/// What is known about one link's distances at its current pose.
struct LinkDistance {
  WarmStart warm;
  double lower = 0.0, upper = kInf;  // bounds on the object distance
  double table = kInf;               // distance to the table (kInf without one)
  bool current = false;              // lower / upper / table were evaluated at the link's current pose
  /// (current only) `lower` stands in for an FCL distance not queried yet; upper is then kInf.
  /// The link cannot touch the object (lower >= contact tolerance).
  bool deferred = false;
  double carried_lower = 0.0;        // a lower bound on the object distance at the current pose
};

/// Evaluates the link's distances at pose T (c.current becomes true). With pruning, an FCL query
/// whose answer cannot make the link touch is deferred; without, advancing_bounds(). `bound`: a
/// further lower bound on the object distance, used like the box bound (the larger one counts).
void evaluate_link(const SimScene& s, int link, const Iso3& T, LinkDistance& c, int& queries, double bound = -kInf);

/// Resolves deferred queries. `limit` is the minimum of the step terms known so far; deferred
/// link k (entry *c[k]) has the term term(k, d) for object distance d (increasing in d), and
/// inverse(k, t) is the distance giving term t. Deferred links whose bound gives a term below
/// the limit are queried, lowest bound first, each by query(k, cap) capped at the distance that
/// would lower the limit. Returns the minimum over all terms: the same as if every deferred
/// link had been queried. count <= 64.
template <class Term, class Inverse, class Query>
double resolve_deferred(LinkDistance* const* c, int count, double limit, Term term, Inverse inverse, Query query) {
  uint64_t tried = 0;  // each link is queried at most once
  for (;;) {
    int best = -1;
    double best_term = limit;
    for (int k = 0; k < count; ++k)
      if (!(tried >> k & 1) && c[k]->deferred && term(k, c[k]->lower) < best_term)
        best = k, best_term = term(k, c[k]->lower);
    if (best < 0) return limit;
    tried |= uint64_t{1} << best;
    LinkDistance& b = *c[best];
    // a hair above the limit's distance, so that round-off in inverse() cannot hide a term
    // equal to the limit
    const double cap = inverse(best, limit) * (1.0 + 1e-12) + 1e-12;
    const double d = query(best, cap);
    if (d < kInf) {
      b.lower = b.upper = d, b.deferred = false;
      limit = std::min(limit, term(best, d));
    } else {
      b.lower = std::max(b.lower, cap);  // still deferred, with a term at or above the limit
    }
  }
}

}  // namespace bayesgrasp::sim
