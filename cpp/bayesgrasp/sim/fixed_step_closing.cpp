// The GraspIt!-style reference closing: the actuator of each finger advances in fixed steps
// with a boolean collision check (FCL primitives) after each; on a collision the contact is
// located by bisection until the fastest link point moves less than the contact tolerance,
// then the breakaway rule applies as in closing.cpp.
#include <algorithm>

#include "bayesgrasp/sim/closing.hpp"
#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

class FixedStepCloser {
 public:
  FixedStepCloser(const SimScene& s, const Iso3& H, int f, Eigen::VectorXd& q, double step, int& queries,
                  int& iterations)
      : s_(s), H_(H), f_(f), F_(s.hand.fingers()[f]), n_(static_cast<int>(F_.phalanges.size())), step_(step),
        spread_(q[0]), angles_(q.data() + F_.first_joint), queries_(queries), iterations_(iterations) {}

  void run() {
    double t = 0.0;
    double a[kMaxPhalanges];
    for (int it = 0; it < s_.options.max_iterations * 10; ++it) {
      first_ = moving_phalanges(F_, frozen_, angles_, moving_);
      if (first_ == n_) break;
      ++iterations_;
      const double t_new = t + step_;
      angles_at(t_new, a);
      const int h = hit_phalanx(a);
      if (h < 0) {
        t = t_new;
        std::copy(a, a + n_, angles_);
        continue;
      }
      const int hit = bisect_contact(t, t_new, h, a);
      std::copy(a, a + n_, angles_);
      for (int i = 0; i <= hit; ++i) frozen_[i] = true;
    }
  }

 private:
  /// The finger's angles at actuator parameter t: the moving phalanges follow the coupling.
  void angles_at(double t, double* out) const {
    for (int i = 0; i < n_; ++i) {
      const Phalanx& P = F_.phalanges[i];
      out[i] = moving_[i] ? std::clamp(P.offset + P.ratio * t, P.lower, P.upper) : angles_[i];
    }
  }

  /// At angles a, the last moving link that hits the table or the object, or -1.
  int hit_phalanx(const double* a) {
    s_.hand.phalanx_poses(H_, f_, spread_, a, T_);
    int h = -1;
    for (int j = first_; j < n_; ++j) {
      const int link = F_.phalanges[j].link;
      const bool hits = (s_.options.table && table_distance(s_.links[link], T_[j]) < 0.0) ||
                        collides(s_, link, T_[j], queries_);
      if (hits) h = j;
    }
    return h;
  }

  /// Bisection on [t, t_new] (free at t, a hit of phalanx h at t_new) until the fastest link
  /// point moves less than the tolerance; leaves the free angles in a, returns the phalanx hit.
  int bisect_contact(double& t, double t_new, int h, double* a) {
    double max_speed = 0.0;
    for (int j = first_; j < n_; ++j)
      max_speed = std::max(max_speed, link_speed(F_, s_.fingers[f_], moving_, first_, j));
    double lo = t, hi = t_new;
    int hit = h;
    while ((hi - lo) * max_speed > s_.options.contact_tolerance) {
      const double mid = 0.5 * (lo + hi);
      angles_at(mid, a);
      const int hm = hit_phalanx(a);
      if (hm >= 0) hi = mid, hit = hm;
      else lo = mid;
    }
    t = lo;
    angles_at(t, a);
    return hit;
  }

  const SimScene& s_;
  const Iso3& H_;
  const int f_;
  const Finger& F_;
  const int n_;
  const double step_, spread_;
  double* angles_;  // the finger's entries of q
  int& queries_;
  int& iterations_;
  bool frozen_[kMaxPhalanges] = {false};
  bool moving_[kMaxPhalanges] = {false};
  int first_ = 0;
  Iso3 T_[kMaxPhalanges];
};

}  // namespace

GraspResult close_hand_fixed_step(const SimScene& s, const Iso3& H, double spread, double step) {
  GraspResult r = open_hand(s, H, spread);
  if (starts_in_collision(s, r)) return r;
  for (int f = 0; f < static_cast<int>(s.hand.fingers().size()); ++f)
    FixedStepCloser(s, H, f, r.joints, step, r.distance_queries, r.iterations).run();
  collect_contacts(s, std::vector<LinkDistance>(s.hand.num_links()), r);
  return r;
}

}  // namespace bayesgrasp::sim
