// Closing by conservative advancement with breakaway (see grasp_simulator.hpp).
//
// Per finger, one step: the moving phalanges (not frozen, below their upper limit); the
// distances of the links they move; a link within the tolerance that moves into the object or
// the table freezes its phalanx and the earlier ones (breakaway); otherwise the actuator
// advances by the safe step dt = min over the links of (d - tol / 2) / v (and the joint
// limits), where v is the link's speed bound (finger_motion.hpp). A link within the tolerance
// whose motion is not clearly into the obstacle slides: it advances by trial steps of kSlide
// travel, checked afterwards and refined by bisection when blocked (GraspIt!-style).
#include <algorithm>

#include "bayesgrasp/sim/closing.hpp"
#include "bayesgrasp/sim/distance_bounds.hpp"

namespace bayesgrasp::sim {

namespace {

constexpr double kSlide = 2e-3;        // trial travel of a link touching but not moving in (m)
constexpr double kSlideMargin = 2e-5;  // a sliding link stops this close to the object (m)

/// Closes one finger of the hand at H; `q` (the full joint vector) and the link distances are
/// updated in place.
class FingerCloser {
 public:
  FingerCloser(const SimScene& s, const Iso3& H, int f, Eigen::VectorXd& q, std::vector<LinkDistance>& known,
               int& queries, int& iterations)
      : s_(s), H_(H), f_(f), F_(s.hand.fingers()[f]), motion_(s.fingers[f]), n_(static_cast<int>(F_.phalanges.size())),
        tol_(s.options.contact_tolerance), spread_(q[0]), angles_(q.data() + F_.first_joint), known_(known),
        queries_(queries), iterations_(iterations) {}

  void run() {
    update_poses();
    sees_object_ = finger_sees_object();
    for (int it = 0; it < s_.options.max_iterations; ++it) {
      first_ = moving_phalanges(F_, frozen_, angles_, moving_);
      if (first_ == n_) break;
      bool sliding[kMaxPhalanges] = {false};
      const int touching = touching_phalanx(sliding);
      if (touching >= 0) {
        freeze_through(touching);
        continue;
      }
      ++iterations_;
      bool any_sliding = false;
      const double dt = safe_step(sliding, any_sliding);
      const double t_old = t_;
      t_ += dt;
      set_actuator(t_);
      carry_bounds(dt);
      if (any_sliding) stop_blocked_sliding(sliding, t_old);
    }
  }

 private:
  LinkDistance& known(int j) { return known_[F_.phalanges[j].link]; }
  void update_poses() { s_.hand.phalanx_poses(H_, f_, spread_, angles_, T_); }
  /// A contact on phalanx j: breakaway freezes 0..j (the later ones keep closing); a linkage
  /// stops the whole finger.
  void freeze_through(int j) {
    const int last = s_.hand.closing() == Closing::Linkage ? n_ - 1 : j;
    for (int i = 0; i <= last; ++i) frozen_[i] = true;
  }

  /// Culling: a finger whose whole reach (a sphere about its first phalanx joint) misses the
  /// object's box only sees the table.
  bool finger_sees_object() const {
    const Eigen::AlignedBox3d& box = s_.object.box;
    const Vec3 j0 = H_ * (F_.base + F_.knuckle_length * s_.hand.finger_direction(f_, spread_));
    const double gap = (box.min() - j0).cwiseMax(j0 - box.max()).cwiseMax(0.0).norm();
    return gap <= motion_.reach + tol_;
  }

  /// Evaluates the links the moving phalanges move (those not evaluated at their pose yet)
  /// and returns the last phalanx that touches and moves into the object or the table (-1 if
  /// none); touching links that do not move in are marked sliding.
  int touching_phalanx(bool* sliding) {
    int touching = -1;
    for (int j = first_; j < n_; ++j) {
      const int link = F_.phalanges[j].link;
      LinkDistance& c = known(j);
      if (!c.current) {
        if (sees_object_) {
          evaluate_link(s_, link, T_[j], c, queries_);
        } else {
          c.lower = kInf, c.upper = kInf, c.deferred = false;
          c.table = s_.options.table ? table_distance(s_.links[link], T_[j]) : kInf;
          c.current = true;
        }
      }
      if (c.upper < tol_ || c.table < tol_) {
        if (moves_in(j, c)) touching = j;
        else sliding[j] = true;
      }
    }
    return touching;
  }

  /// Velocity per unit of t of point p (world) of phalanx j's link.
  Vec3 velocity(int j, const Vec3& p) const {
    Vec3 v = Vec3::Zero();
    for (int i = first_; i <= j; ++i) {
      if (!moving_[i]) continue;
      if (F_.phalanges[i].prismatic) v -= F_.phalanges[i].ratio * T_[i].linear().col(2);  // inwards, -d_f
      else v += F_.phalanges[i].ratio * T_[i].linear().col(1).cross(p - T_[i].translation());
    }
    return v;
  }

  /// Whether phalanx j, within the tolerance of the object or the table, moves into it (the
  /// velocity of its nearest point points against the outward normal). A link whose motion
  /// separates it from a touching obstacle (e.g. a proximal capsule resting on an edge at the
  /// start and rotating away) is not stopped.
  bool moves_in(int j, const LinkDistance& c) {
    const int link = F_.phalanges[j].link;
    if (c.upper < tol_) {
      const NearestPoints e = nearest_points(s_, link, T_[j], queries_);
      if (e.distance < tol_) {
        if (e.distance <= 0.0 || e.triangle < 0) return true;
        const Vec3 n = contact_normal(s_, e);
        const Vec3 v = velocity(j, e.link_point);
        if (v.dot(n) < -0.2 * v.norm()) return true;  // clearly moving in; else it slides
      }
    }
    if (c.table < tol_) {
      const Vec3 v = velocity(j, lowest_point(s_.links[link], T_[j]));
      if (v.z() < -0.2 * v.norm()) return true;
    }
    return false;
  }

  /// The safe step in t: the minimum over the links' terms (d - tol / 2) / v, d = min(object,
  /// table), and the joint limits; sliding links take a trial step of kSlide travel.
  /// (min(a, b) - x) / v = min((a - x) / v, (b - x) / v) exactly in floating point, so the
  /// object and table terms are taken separately: the object terms of deferred links are then
  /// resolved last, against the others' minimum.
  double safe_step(const bool* sliding, bool& any_sliding) {
    double dt = kInf;
    max_speed_ = 0.0;
    LinkDistance* deferred[kMaxPhalanges];
    int deferred_phalanx[kMaxPhalanges], n_deferred = 0;
    for (int j = first_; j < n_; ++j) {
      speed_[j] = 0.0;
      const double v = link_speed(F_, motion_, moving_, first_, j);
      if (v <= 0.0) continue;
      max_speed_ = std::max(max_speed_, v);
      speed_[j] = v;
      LinkDistance& c = known(j);
      if (sliding[j]) {
        any_sliding = true;
        dt = std::min(dt, kSlide / v);
      } else {
        dt = std::min(dt, (c.table - 0.5 * tol_) / v);
        if (c.deferred) deferred[n_deferred] = &c, deferred_phalanx[n_deferred++] = j;
        else dt = std::min(dt, (c.lower - 0.5 * tol_) / v);
      }
    }
    for (int i = first_; i < n_; ++i)
      if (moving_[i]) {
        const Phalanx& P = F_.phalanges[i];
        dt = std::min(dt, (P.closing_limit() - P.offset) / P.ratio - t_);
      }
    dt = resolve_deferred(
        deferred, n_deferred, dt, [&](int k, double d) { return (d - 0.5 * tol_) / speed_[deferred_phalanx[k]]; },
        [&](int k, double step) { return step * speed_[deferred_phalanx[k]] + 0.5 * tol_; },
        [&](int k, double cap) {
          const int j = deferred_phalanx[k];
          return distance_below(s_, F_.phalanges[j].link, T_[j], cap, queries_, &deferred[k]->warm);
        });
    return std::max(dt, 0.0);
  }

  /// Moves the moving phalanges to actuator parameter t (the coupling law, clamped).
  void set_actuator(double t) {
    for (int i = first_; i < n_; ++i)
      if (moving_[i]) {
        const Phalanx& P = F_.phalanges[i];
        const double q = P.offset + P.ratio * t;  // snapped onto the limit it heads for when within 1e-12
        angles_[i] = P.ratio > 0 && q >= P.upper - 1e-12   ? P.upper
                     : P.ratio < 0 && q <= P.lower + 1e-12 ? P.lower
                                                           : std::clamp(q, P.lower, P.upper);
      }
    update_poses();
  }

  /// After a step of dt, every moved link's distance is at least its lower bound minus its travel.
  void carry_bounds(double dt) {
    for (int j = first_; j < n_; ++j) {
      LinkDistance& c = known(j);
      c.current = false;
      c.carried_lower = std::max(0.0, c.lower - speed_[j] * dt);
    }
  }

  /// The last sliding phalanx that is blocked at the current pose, or -1.
  int blocked_sliding_phalanx(const bool* sliding) {
    int h = -1;
    for (int j = first_; j < n_; ++j)
      if (sliding[j] && sliding_blocked(s_, F_.phalanges[j].link, T_[j], kSlideMargin, queries_)) h = j;
    return h;
  }

  /// The sliding links were only assumed to slide or separate: check them, and on a collision
  /// find the contact by bisection on [t_old, t] (GraspIt!-style) and stop there.
  void stop_blocked_sliding(const bool* sliding, double t_old) {
    int h = blocked_sliding_phalanx(sliding);
    if (h < 0) return;
    double lo = t_old, hi = t_;
    while ((hi - lo) * max_speed_ > tol_) {
      const double mid = 0.5 * (lo + hi);
      set_actuator(mid);
      const int hm = blocked_sliding_phalanx(sliding);
      if (hm >= 0) hi = mid, h = hm;
      else lo = mid;
    }
    t_ = lo;
    set_actuator(t_);
    freeze_through(h);
  }

  const SimScene& s_;
  const Iso3& H_;
  const int f_;
  const Finger& F_;
  const FingerMotion& motion_;
  const int n_;
  const double tol_, spread_;
  double* angles_;  // the finger's entries of q
  std::vector<LinkDistance>& known_;
  int& queries_;
  int& iterations_;
  bool sees_object_ = true;
  double t_ = 0.0;  // actuator parameter
  bool frozen_[kMaxPhalanges] = {false};
  bool moving_[kMaxPhalanges] = {false};
  int first_ = 0;  // first moving phalanx
  Iso3 T_[kMaxPhalanges];
  double speed_[kMaxPhalanges] = {0.0};  // link speed bounds of the current step
  double max_speed_ = 0.0;
};

}  // namespace

GraspResult close_hand(const SimScene& s, const Iso3& H, double spread, const std::vector<LinkDistance>* from_approach) {
  GraspResult r = open_hand(s, H, spread);
  std::vector<LinkDistance> known(s.hand.num_links());
  if (from_approach) known = *from_approach;
  else if (starts_in_collision(s, r)) return r;
  for (int f = 0; f < static_cast<int>(s.hand.fingers().size()); ++f)
    FingerCloser(s, H, f, r.joints, known, r.distance_queries, r.iterations).run();
  collect_contacts(s, known, r);
  return r;
}

}  // namespace bayesgrasp::sim
