// A multi-fingered hand described by a data file (JSON): palm, fingers as chains of
// phalanges, collision shapes per link, and the closing scheme (coupled joints with
// breakaway). Another hand is another file, not new code.
//
// Frames. The hand frame has its origin at the centre of the palm face and +z along the
// approach direction (out of the palm). Finger f has a base point b_f in the hand frame and
// an outward direction d_f(s) = Rz(base_yaw_f + spread_sign_f * s) * x in the palm plane,
// where s is the spread joint. Its first phalanx joint sits at b_f + knuckle_length * d_f.
// Every phalanx joint axis is a_f = d_f x z, so a cumulative phalanx angle Theta turns the
// link direction from d_f (Theta = 0, flat in the palm plane, pointing outwards) towards +z
// (Theta = 90 deg) and then inwards. A finger with a roll psi_f (a thumb whose flexion axis is
// not in the palm plane) has its whole plane turned about d_f by psi_f: axis
// Rot(d_f, psi_f) a_f = cos(psi_f) a_f - sin(psi_f) z, and Theta = 90 deg points along
// Rot(d_f, psi_f) z.
//
// Link frames. Link 0 is the palm (frame = hand frame). Then, per finger, its knuckle (frame:
// origin at b_f, x = d_f, y = a_f, z = x X y = -z_hand) and its phalanges (frame: origin at the
// joint, x along the link, y = a_f, z = x X y). The grasping (inner) face of a phalanx is its
// local -z side. Shapes are given in link frames.
//
// Joint vector q (radians): [spread, f0 phalanx 0, f0 phalanx 1, ..., f1 phalanx 0, ...];
// phalanx angles are relative to the previous phalanx (or to the palm plane for phalanx 0).
//
// Closing. Each finger has one actuator parameter t >= 0; while free, phalanx j follows
// q_j(t) = offset_j + ratio_j * t, clamped to [lower_j, upper_j]. Three schemes (the hand file's
// "closing"):
//  * breakaway (the BH8's TorqueSwitch; every ratio >= 0): when phalanx k is stopped by a contact,
//    phalanges 0..k freeze, and phalanges after k keep closing; a phalanx that reaches its upper
//    limit stops alone.
//  * linkage (a four-bar or a mimic chain, e.g. a 2F-85's pads kept parallel): the first ratio
//    > 0, the others of any sign (a negative ratio turns the phalanx back as the finger closes:
//    -1 keeps it at a constant absolute angle); a contact on any phalanx stops the whole finger.
//  * independent (a dexterous hand, one motor per joint; every ratio > 0, the closing
//    controller's relative joint speeds): closes as breakaway does (a contact on phalanx k stops
//    the joints that would push k into it, 0..k), and in the lift test every joint presses with
//    its own motor's torque (no coupling, no worm lock).
// A phalanx that reaches the limit it moves towards (upper for ratio > 0, lower for ratio < 0)
// stops alone. The finger is done when every phalanx is frozen or at that limit.
//
// Parallel jaws. A finger whose only phalanx is prismatic translates along -d_f (inwards) by
// q metres instead of turning (Phalanx::prismatic).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp {

/// A collision primitive in a link frame.
struct Shape {
  enum class Type { Box, Capsule, Convex };
  Type type = Type::Box;
  Vec3 center = Vec3::Zero();        // Box: centre (box axes = link axes); Convex: the vertices' mean
  Vec3 half_extents = Vec3::Zero();  // Box
  Vec3 p0 = Vec3::Zero();            // Capsule: segment end points and radius
  Vec3 p1 = Vec3::Zero();
  double radius = 0.0;               // Capsule; Convex: the largest distance of a vertex from center
  // Convex: a closed convex polyhedron (a mesh link's hull, a cylinder's prism): its vertices,
  // its triangles wound counter-clockwise seen from outside, and per triangle the outward plane
  // (unit normal n, offset d: n . x <= d inside).
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> faces;
  std::vector<Eigen::Vector4d> planes;
  /// Convex: the largest plane distance n . p - d over the faces (<= 0 inside; a lower bound on
  /// the distance outside, exact inside as minus the depth).
  double plane_distance(const Vec3& p) const;
};

struct Phalanx {
  std::string name;
  double length = 0.0;  // joint to next joint / fingertip (m)
  double lower = 0.0, upper = 0.0;  // joint limits (rad; m for a prismatic joint)
  double offset = 0.0, ratio = 1.0; // coupling: q(t) = offset + ratio * t
  /// The limit the coupling moves this joint towards (upper for ratio > 0, lower for ratio < 0).
  double closing_limit() const { return ratio < 0 ? lower : upper; }
  double torque = 0.0;  // N m (N for a prismatic joint): the finger motor's limit at this joint while it drives it
  // A prismatic phalanx (a parallel jaw, its finger's only phalanx): its link points along the
  // approach (the revolute frame at Theta = 90 deg: x = +z_hand, local +z = d_f outwards, the
  // grasping face local -z) and its joint value is the travel inwards from the knuckle's end:
  // origin = b_f + (knuckle_length - q) d_f.
  bool prismatic = false;
  std::vector<Shape> shapes;
  int link = -1;  // index into HandModel::links
};

struct Finger {
  std::string name;
  Vec3 base = Vec3::Zero();  // spread axis (hand frame)
  double base_yaw = 0.0;     // outward direction at spread 0 (rad, about +z)
  double roll = 0.0;         // the finger plane's turn about its outward direction (rad; 0: axes in the palm plane)
  double spread_sign = 0.0;  // d(yaw)/d(spread): +1, -1, or 0 for a fixed finger
  double knuckle_length = 0.0;
  std::vector<Shape> knuckle_shapes;
  int knuckle_link = -1;
  std::vector<Phalanx> phalanges;
  int first_joint = -1;  // index in q of phalanx 0
  /// Actuator parameter at which every phalanx has reached its upper limit.
  double t_max() const;
};

enum class Closing { Breakaway, Linkage, Independent };

struct Link {
  std::string name;
  int finger = -1;   // -1 for the palm
  int phalanx = -1;  // -1 for palm and knuckles
  std::vector<Shape> shapes;
};

/// `d` normalised; throws std::invalid_argument naming `name` if d is not finite or of zero
/// length (below 1e-12).
Vec3 unit_direction(const Vec3& d, const char* name = "direction");

class HandModel {
 public:
  /// Parses the JSON text of a hand file; throws std::invalid_argument naming what is wrong.
  static HandModel from_json(const std::string& json_text);
  static HandModel from_file(const std::string& path);

  const std::string& name() const { return name_; }
  const std::vector<Finger>& fingers() const { return fingers_; }
  const std::vector<Link>& links() const { return links_; }
  int num_joints() const { return num_joints_; }
  int num_links() const { return static_cast<int>(links_.size()); }
  double spread_lower() const { return spread_lower_; }
  double spread_upper() const { return spread_upper_; }
  double spread_default() const { return spread_default_; }
  Closing closing() const { return closing_; }
  /// Indices into q of the joints the "fingers read" measurement uses (the file's measured_joints).
  const std::vector<int>& measured_joints() const { return measured_joints_; }

  /// Joint vector with the given spread and every finger at actuator parameter t.
  Eigen::VectorXd coupled_joints(double spread, double t = 0.0) const;
  /// Same, one actuator parameter per finger.
  Eigen::VectorXd coupled_joints(double spread, const Eigen::VectorXd& t_per_finger) const;
  /// Phalanx j of finger f at actuator parameter t (coupling law, clamped to limits).
  double coupled_angle(int finger, int phalanx, double t) const;

  /// Throws std::invalid_argument (naming `name`) if q has the wrong size, is not finite, or
  /// is outside the joint limits by more than `tol`.
  void check_joints(const Eigen::VectorXd& q, double tol = 1e-9, const char* name = "joints") const;
  /// Throws std::invalid_argument (naming `name`) unless the spread is finite and within its
  /// limits (1e-12 rad of slack).
  void check_spread(double spread, const char* name = "spread") const;

  /// Outward direction of finger f at spread s (hand frame, unit, in the palm plane).
  Vec3 finger_direction(int finger, double spread) const;

  /// Poses of every link in the frame of `hand_pose` (world if hand_pose is the hand's
  /// world pose), indexed like links().
  std::vector<Iso3> link_poses(const Iso3& hand_pose, const Eigen::VectorXd& q) const;
  /// Poses of the first `count` phalanges of one finger (all of them if count < 0) in the frame
  /// of `hand_pose`, at spread `spread` and the finger's relative phalanx angles `angles`
  /// (its entries of q, from Finger::first_joint). `out` has room for them. No allocation:
  /// the simulator calls it at every step. link_poses() and phalanx_pose() use it too.
  void phalanx_poses(const Iso3& hand_pose, int finger, double spread, const double* angles, Iso3* out,
                     int count = -1) const;
  /// Pose of one finger's phalanx j (and its predecessors) - cheaper than all links.
  Iso3 phalanx_pose(const Iso3& hand_pose, int finger, int phalanx, const Eigen::VectorXd& q) const;
  /// Fingertip (end of the last phalanx) of finger f.
  Vec3 fingertip(const Iso3& hand_pose, int finger, const Eigen::VectorXd& q) const;

  /// World pose of a palm-down hand above the table at (x, y, yaw), palm face at height z:
  /// hand +z = world -z, hand x = world Rz(yaw) x.
  static Iso3 top_grasp_pose(double x, double y, double yaw, double z);

  /// World pose of a hand approaching along `direction` (hand +z; normalised here) with `roll`,
  /// palm centre at `palm`. Roll convention: the palm-down top-grasp hand at yaw = roll
  /// (top_grasp_pose) tilted by the smallest rotation taking world -z onto the direction;
  /// equivalently, roll turns the hand right-handedly about -direction (for direction -z it is
  /// the top grasp's yaw, exactly: the same matrix). For direction +z (from below) the tilt is a
  /// half turn about world x (the hand's rotation is then Rz(-roll)). Throws std::invalid_argument naming `direction` (zero or not
  /// finite), `roll` or `palm` (not finite).
  static Iso3 approach_pose(const Vec3& direction, double roll, const Vec3& palm);

 private:
  std::string name_;
  std::vector<Finger> fingers_;
  std::vector<Link> links_;
  int num_joints_ = 1;
  std::vector<int> measured_joints_;
  Closing closing_ = Closing::Breakaway;
  double spread_lower_ = 0.0, spread_upper_ = 0.0, spread_default_ = 0.0;
};

}  // namespace bayesgrasp
