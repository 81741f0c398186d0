#include "bayesgrasp/sim/finger_motion.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bayesgrasp::sim {

std::vector<FingerMotion> make_finger_motion(const HandModel& hand, const LinkShapes& links) {
  std::vector<FingerMotion> out(hand.fingers().size());
  for (size_t f = 0; f < hand.fingers().size(); ++f) {
    const Finger& F = hand.fingers()[f];
    const int n = static_cast<int>(F.phalanges.size());
    if (n > kMaxPhalanges)
      throw std::invalid_argument("hand: at most " + std::to_string(kMaxPhalanges) + " phalanges per finger");
    FingerMotion& m = out[f];
    m.arm.assign(n, std::vector<double>(n, 0.0));
    for (int i = 0; i < n; ++i) {
      double along = 0.0;
      for (int j = i; j < n; ++j) {
        // a prismatic joint moves every point of its link by exactly its travel
        m.arm[i][j] = F.phalanges[i].prismatic ? 1.0 : along + link_reach(links[F.phalanges[j].link]);
        along += F.phalanges[j].length;
      }
      m.reach = std::max(m.reach, F.phalanges[i].prismatic
                                      ? link_reach(links[F.phalanges[i].link]) + F.phalanges[i].upper - F.phalanges[i].lower
                                      : m.arm[0][i]);
    }
  }
  return out;
}

int moving_phalanges(const Finger& F, const bool* frozen, const double* angles, bool* moving) {
  const int n = static_cast<int>(F.phalanges.size());
  int first = n;
  for (int i = 0; i < n; ++i) {
    const Phalanx& P = F.phalanges[i];
    // moving towards the limit its coupling heads for (upper, or lower for a negative ratio)
    moving[i] = !frozen[i] && (P.ratio > 0 ? angles[i] < P.upper : P.ratio < 0 && angles[i] > P.lower);
    if (moving[i] && first == n) first = i;
  }
  return first;
}

double link_speed(const Finger& F, const FingerMotion& motion, const bool* moving, int first, int j) {
  double v = 0.0;
  for (int i = first; i <= j; ++i)
    if (moving[i]) v += std::abs(F.phalanges[i].ratio) * motion.arm[i][j];  // a bound: |ratio| for either sign
  return v;
}

}  // namespace bayesgrasp::sim
