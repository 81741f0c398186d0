// Physical lift test (Bullet): the simulated stand-in for "lift it and see".
//
// After the contact simulator has closed the hand, the grasp is replayed in a Bullet world:
//  * the object is a dynamic rigid body with the mass, centre of mass and inertia of its
//    mesh at `density` (geometry/mass_properties; body frame = principal axes at the
//    centre of mass);
//  * the palm (with the knuckles, i.e. the spread is frozen) is a kinematic body that
//    follows a scripted trajectory;
//  * every phalanx is a dynamic body (mass `link_mass`, centre of mass on its joint axis)
//    hinged to its parent at its joint, starting at the given closed joint angles, with a
//    joint motor that keeps closing at `closing_speed` with at most `finger_torque` (N m):
//    the fingers keep squeezing with a bounded force, like the real hand's motors. A joint
//    cannot open past its given angle (the Barrett hand's worm drives are not
//    backdrivable) and closes at most `squeeze_travel` further (or to its upper limit), so
//    a finger that touches nothing moves only a little;
//  * the hand collides only with the object; the object also with the table (z = 0, if
//    `table`); gravity is -9.81 m/s^2 along z.
// Friction: two friction directions per contact (Bullet's SOLVER_USE_2_FRICTION_DIRECTIONS).
// Bullet's default solves friction along one tangent only (the sliding direction, or an
// arbitrary tangent for a contact at rest), so an object held at rest by side contacts slides
// freely along the other tangent with its friction far from saturated; with both directions
// far more force-closure grasps are held (see BENCHMARKS.md).
// Time step. Verdicts near the 2 cm threshold depend on the step (velocity-level contacts and
// iterative joints); the default, 1/480 s, trades agreement with a fine step (1/1440 s) for
// speed (BENCHMARKS.md gives the agreement per step); pass a finer step for a closer answer.
// Script (fixed time step, no randomness: deterministic):
//   squeeze  `squeeze_time` s, the palm still (the fingers tighten, the object may settle);
//   lift     the palm rises `lift_height` (10 cm) in `lift_time` s (smooth cosine profile);
//   shake    `shake_time` s of a gentle three-axis shake of amplitude `shake_amplitude`
//            at `shake_frequency` Hz (x, y, z a third of a period apart, sin^2 envelope so
//            the palm's velocity is continuous);
//   hold     `hold_time` s still.
// Outcome: displacement = distance between the object's centre of mass in the palm frame at
// the end and after the squeeze (the squeeze may seat the object against the palm; that
// settling is reported separately as squeeze_displacement); lifted = displacement <
// `success_distance` (2 cm) and the simulation stayed finite. With the table present, an
// object the hand does not hold stays on the table and moves ~lift_height relative to the
// palm. The run stops early once the object is max(5 cm, 2.5 x success_distance) away
// (it is lost for good); displacement is then the one at that moment.
//
// Object collision shape (`shape`):
//  * ConvexHull: Bullet's btConvexHullShape of the mesh's hull vertices (fast, exact for
//    convex objects, fills cavities and handles of concave ones);
//  * Tetrahedra: a compound of one tetrahedron per triangle, from the triangle to an apex
//    inside the solid (along the inward normal, `tet_depth` deep, or less where a ray finds
//    the opposite wall sooner) - a solid skin that keeps concavities (a mug's opening and
//    handle) with convex pieces only, robust with Bullet's convex-convex contacts;
//  * Decomposition: a compound of the convex hulls of given pieces (`convex_pieces`, an
//    approximate convex decomposition of the object computed once per mesh, e.g. by CoACD
//    in python/bayesgrasp/physics.py) - a handful of convex hulls instead of one
//    tetrahedron per triangle: keeps the opening and the handle's hole, far cheaper;
//  * Auto (default): ConvexHull if the hull's volume is within 5% of the mesh's volume.
//    Otherwise (concave) it is decided per grasp: the hull if no hand link reaches more
//    than 1 mm into the hull at the start (the hand then meets the object from outside,
//    where hull and mesh agree near the contacts), else the concave shape (the hand is in a
//    concavity: a mug's opening or handle): Decomposition if pieces were given, else
//    Tetrahedra. See bench/bench_physics.cpp and BENCHMARKS.md for the costs (hull and
//    decomposition are far cheaper than tetrahedra).
// Collision margins are `margin` (0.5 mm) on every shape (Bullet's default 4 cm is meant for
// metre-sized bodies).
// Speed. Bullet runs a GJK query at every step for every pair of child shapes (a hand link's
// capsule or box, one convex piece of the object) whose bounding boxes overlap; with a finger
// inside a mug that is most of the pairs, nearly all of them apart. With
// `skip_separated_pairs` a pair found apart keeps a separating axis and a lower bound on its
// separation that is updated from the two shapes' motion; while the bound exceeds the
// contact-breaking distance and the pair has no contact point, Bullet's query (which would
// add no point) is skipped (physics/separated_pair_skip.hpp). Same results, faster on concave
// objects (see BENCHMARKS.md).
//
// Files: lift_object (object preparation, per-grasp shape, the object's body), hand_bodies
// (palm, phalanges, hinges and motors), lift_script (trajectory and outcome), bullet_world
// (the world and its ownership), separated_pair_skip (the narrowphase skip).
//
// Thread safety: LiftTester is immutable after construction; each run builds its own Bullet
// world, so run() may be called from many threads at once.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp {

struct LiftOptions {
  enum class Shape { Auto, ConvexHull, Tetrahedra, Decomposition };
  double mu = 0.5;              // friction between the hand and the object
  double table_mu = 0.5;        // friction between the object and the table
  double density = 1000.0;      // kg/m^3 (mass from the mesh)
  double time_step = 1.0 / 480.0;  // s; see the note on time steps above
  int solver_iterations = 10;
  double squeeze_time = 0.15;   // s
  double lift_height = 0.10;    // m
  double lift_time = 0.40;      // s
  double shake_amplitude = 0.01;  // m
  double shake_frequency = 3.0;   // Hz
  double shake_time = 0.5;        // s
  double hold_time = 0.1;         // s
  double finger_torque = 0.5;     // N m, per phalanx joint motor (~5 N at the fingertip)
  double closing_speed = 1.0;     // rad/s, motor target velocity (closing)
  double squeeze_travel = 0.15;   // rad a joint may close beyond its given angle
  double link_mass = 0.08;        // kg per phalanx
  double success_distance = 0.02; // m
  bool table = true;
  Shape shape = Shape::Auto;
  double tet_depth = 0.01;  // m, for Shape::Tetrahedra
  double margin = 5e-4;     // m, collision margin
  // Skip Bullet's narrowphase query for a hand shape and an object piece that a
  // conservative bound proves apart (see the note on speed above); the simulation is the
  // same with or without (tests/cpp/test_physics.cpp checks equal results), only faster.
  bool skip_separated_pairs = true;
};

struct LiftResult {
  bool lifted = false;
  double displacement = 0.0;  // m, object's centre of mass relative to the palm, end vs after the squeeze
  double rotation = 0.0;      // rad, object's rotation relative to the palm, end vs after the squeeze
  double squeeze_displacement = 0.0;  // m, how far the squeeze itself moved the object (in the palm frame)
  double height_gain = 0.0;   // m, world z of the object's centre of mass, end minus start
  bool finite = true;         // false if the simulation blew up (then lifted = false)
  bool tetrahedra = false;    // the object used the tetrahedra shape
  LiftOptions::Shape shape = LiftOptions::Shape::ConvexHull;  // the shape used (never Auto)
  int steps = 0;
  long skipped_queries = 0;  // narrowphase queries skipped (LiftOptions::skip_separated_pairs)
};

class LiftTester {
 public:
  /// `object` in the world frame (the frame of the hand poses). `convex_pieces`: optional
  /// approximate convex decomposition of the object (world frame, one (K, 3) point set per
  /// piece; each piece's convex hull is used), needed by Shape::Decomposition and used by
  /// Auto for concave objects. Throws std::invalid_argument for a bad mesh, a mesh
  /// enclosing no volume, bad options, or a piece that is not finite or spans no volume.
  LiftTester(const HandModel& hand, const TriMesh& object, const LiftOptions& options = {},
             const std::vector<Eigen::MatrixX3d>& convex_pieces = {});
  ~LiftTester();
  LiftTester(LiftTester&&) noexcept;
  LiftTester& operator=(LiftTester&&) noexcept;

  const LiftOptions& options() const;
  /// Mass properties of the object used (world frame).
  const MassProperties& mass_properties() const;
  /// The collision shape prepared (never Auto): ConvexHull for convex objects or when
  /// asked; for concave ones under Auto, Decomposition (pieces given) or Tetrahedra (then
  /// each run may still use the hull, see LiftResult::shape).
  LiftOptions::Shape shape() const;
  /// Whether the object counts as concave (hull volume more than 5% above the mesh's).
  bool concave() const;
  /// Number of convex pieces kept (0 without a decomposition).
  int num_pieces() const;

  /// One lift test from the closed grasp (hand pose in the world, joints in HandModel
  /// layout). Throws std::invalid_argument for a non-finite pose or joints of the wrong
  /// size / outside the limits.
  LiftResult run(const Iso3& hand_pose, const Eigen::VectorXd& joints) const;

  /// N lift tests (row i of `joints` with poses[i]) in `threads` threads (0 = all cores,
  /// common/parallel.hpp thread_count; negative is an error), each with its own Bullet
  /// world. Results in input order, identical to run() one by one.
  std::vector<LiftResult> run_batch(const std::vector<Iso3>& poses,
                                    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints,
                                    int threads = 1) const;

  struct Impl;

 private:
  LiftResult simulate(const Iso3& hand_pose, const Eigen::VectorXd& joints) const;  // validated input
  std::unique_ptr<Impl> impl_;
};

/// One-shot convenience: LiftTester(hand, object, options).run(hand_pose, joints).
LiftResult lift_test(const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                     const TriMesh& object, const LiftOptions& options = {});

}  // namespace bayesgrasp
