// HandModel's kinematics: the coupled closing of the fingers, joint checks, link and fingertip
// poses, and hand poses from grasp parameters. Reading a hand file is in hand_file.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp {

namespace {

/// A link's rotation: its x along the finger direction d turned by theta towards +z (the palm
/// normal), its y along d x z.
/// Link frame at cumulative angle theta in the plane of outward direction d (unit, in the palm
/// plane) turned by roll about d: x = cos(theta) d + sin(theta) z', y = a (the joint axis),
/// z = x X y, with a = cos(roll) (d x z) - sin(roll) z and z' = Rot(d, roll) z = cos(roll) z +
/// sin(roll) (d x z).
Eigen::Matrix3d link_rotation(const Vec3& d, double theta, double roll = 0.0) {
  const Vec3 zh = Vec3::UnitZ(), a0 = d.cross(zh);
  const double c = std::cos(roll), s = std::sin(roll);
  const Vec3 z = c * zh + s * a0;
  const Vec3 a = c * a0 - s * zh;
  const Vec3 x = std::cos(theta) * d + std::sin(theta) * z;
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = a;
  R.col(2) = x.cross(a);
  return R;
}

}  // namespace

double Shape::plane_distance(const Vec3& p) const {
  double d = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector4d& pl : planes) d = std::max(d, pl.head<3>().dot(p) - pl[3]);
  return d;
}

double Finger::t_max() const {
  double t = 0.0;
  for (const Phalanx& p : phalanges)
    if (p.ratio != 0) t = std::max(t, (p.closing_limit() - p.offset) / p.ratio);
  return t;
}

double HandModel::coupled_angle(int f, int p, double t) const {
  const Phalanx& ph = fingers_.at(f).phalanges.at(p);
  return std::clamp(ph.offset + ph.ratio * t, ph.lower, ph.upper);
}

Eigen::VectorXd HandModel::coupled_joints(double spread, double t) const {
  return coupled_joints(spread, Eigen::VectorXd::Constant(static_cast<Eigen::Index>(fingers_.size()), t));
}

Eigen::VectorXd HandModel::coupled_joints(double spread, const Eigen::VectorXd& t) const {
  if (t.size() != static_cast<Eigen::Index>(fingers_.size()))
    throw std::invalid_argument("one actuator parameter per finger expected");
  Eigen::VectorXd q(num_joints_);
  q[0] = std::clamp(spread, spread_lower_, spread_upper_);
  for (size_t f = 0; f < fingers_.size(); ++f)
    for (size_t p = 0; p < fingers_[f].phalanges.size(); ++p)
      q[fingers_[f].first_joint + static_cast<int>(p)] = coupled_angle(static_cast<int>(f), static_cast<int>(p), t[f]);
  return q;
}

void HandModel::check_joints(const Eigen::VectorXd& q, double tol, const char* name) const {
  const std::string n(name);
  if (q.size() != num_joints_)
    throw std::invalid_argument(n + ": expected " + std::to_string(num_joints_) + " values, got " +
                                std::to_string(q.size()));
  if (!q.allFinite()) throw std::invalid_argument(n + ": contain NaN or infinity");
  if (q[0] < spread_lower_ - tol || q[0] > spread_upper_ + tol)
    throw std::invalid_argument(n + ": spread outside its limits");
  for (const Finger& f : fingers_)
    for (size_t p = 0; p < f.phalanges.size(); ++p) {
      const double v = q[f.first_joint + static_cast<int>(p)];
      if (v < f.phalanges[p].lower - tol || v > f.phalanges[p].upper + tol)
        throw std::invalid_argument(n + ": " + f.name + "/" + f.phalanges[p].name + " outside its limits");
    }
}

void HandModel::check_spread(double s, const char* name) const {
  if (!std::isfinite(s) || s < spread_lower_ - 1e-12 || s > spread_upper_ + 1e-12)
    throw std::invalid_argument(std::string(name) + ": must lie in [" + std::to_string(spread_lower_) + ", " +
                                std::to_string(spread_upper_) + "] rad, got " + std::to_string(s));
}

Vec3 HandModel::finger_direction(int f, double spread) const {
  const Finger& finger = fingers_.at(f);
  const double yaw = finger.base_yaw + finger.spread_sign * spread;
  return Vec3(std::cos(yaw), std::sin(yaw), 0.0);
}

void HandModel::phalanx_poses(const Iso3& hand_pose, int f, double spread, const double* angles, Iso3* out,
                              int count) const {
  const Finger& finger = fingers_.at(f);
  const int n = count < 0 ? static_cast<int>(finger.phalanges.size()) : count;
  const Vec3 d = finger_direction(f, spread);
  Vec3 joint = finger.base + finger.knuckle_length * d;
  double theta = 0.0;  // cumulative phalanx angle
  Iso3 local = Iso3::Identity();
  for (int p = 0; p < n; ++p) {
    if (finger.phalanges[p].prismatic) {  // a jaw: along the approach, moved inwards by its travel
      local.linear() = link_rotation(d, M_PI / 2);
      local.translation() = joint - angles[p] * d;
      out[p] = hand_pose * local;
      continue;
    }
    theta += angles[p];
    local.linear() = link_rotation(d, theta, finger.roll);
    local.translation() = joint;
    out[p] = hand_pose * local;
    joint += finger.phalanges[p].length * local.linear().col(0);
  }
}

std::vector<Iso3> HandModel::link_poses(const Iso3& hand_pose, const Eigen::VectorXd& q) const {
  std::vector<Iso3> poses(links_.size(), hand_pose);
  std::vector<Iso3> phalanges;
  for (size_t f = 0; f < fingers_.size(); ++f) {
    const Finger& finger = fingers_[f];
    if (finger.knuckle_link >= 0) {
      Iso3 local = Iso3::Identity();
      local.linear() = link_rotation(finger_direction(static_cast<int>(f), q[0]), 0.0, finger.roll);
      local.translation() = finger.base;
      poses[finger.knuckle_link] = hand_pose * local;
    }
    phalanges.resize(finger.phalanges.size());
    phalanx_poses(hand_pose, static_cast<int>(f), q[0], q.data() + finger.first_joint, phalanges.data());
    for (size_t p = 0; p < finger.phalanges.size(); ++p) poses[finger.phalanges[p].link] = phalanges[p];
  }
  return poses;
}

Iso3 HandModel::phalanx_pose(const Iso3& hand_pose, int f, int p, const Eigen::VectorXd& q) const {
  const Finger& finger = fingers_.at(f);
  if (p < 0 || p >= static_cast<int>(finger.phalanges.size())) throw std::invalid_argument("phalanx: out of range");
  std::vector<Iso3> poses(static_cast<size_t>(p) + 1);
  phalanx_poses(hand_pose, f, q[0], q.data() + finger.first_joint, poses.data(), p + 1);
  return poses.back();
}

Vec3 HandModel::fingertip(const Iso3& hand_pose, int f, const Eigen::VectorXd& q) const {
  const Finger& finger = fingers_.at(f);
  const int last = static_cast<int>(finger.phalanges.size()) - 1;
  const Iso3 T = phalanx_pose(hand_pose, f, last, q);
  return T * Vec3(finger.phalanges[last].length, 0.0, 0.0);
}

Iso3 HandModel::top_grasp_pose(double x, double y, double yaw, double z) {
  Iso3 T = Iso3::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix();
  T.translation() = Vec3(x, y, z);
  return T;
}

Vec3 unit_direction(const Vec3& d, const char* name) {
  if (!d.allFinite()) throw std::invalid_argument(std::string(name) + ": contains NaN or infinity");
  const double n = d.norm();
  if (!(n > 1e-12))
    throw std::invalid_argument(std::string(name) + ": must be a non-zero vector, got length " + std::to_string(n));
  return d / n;
}

Iso3 HandModel::approach_pose(const Vec3& direction, double roll, const Vec3& palm) {
  const Vec3 d = unit_direction(direction);
  if (!std::isfinite(roll)) throw std::invalid_argument("roll: must be finite");
  if (!palm.allFinite()) throw std::invalid_argument("palm: contains NaN or infinity");
  Iso3 T = top_grasp_pose(palm.x(), palm.y(), roll, palm.z());
  // The tilt taking -z onto d: about the axis (-z) x d = (d_y, -d_x, 0) by the angle between them.
  const Vec3 axis(d.y(), -d.x(), 0.0);
  const double s = axis.norm();
  if (s == 0.0 && d.z() < 0.0) return T;  // d = -z: the top grasp itself
  const Mat3 tilt = s == 0.0 ? Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix()
                             : Eigen::AngleAxisd(std::atan2(s, -d.z()), axis / s).toRotationMatrix();
  T.linear() = tilt * T.linear();
  return T;
}

}  // namespace bayesgrasp
