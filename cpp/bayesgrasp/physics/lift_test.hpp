// Physical lift test (Bullet): the simulated stand-in for "lift it and see".
//
// After the contact simulator has closed the hand, the grasp is replayed in a Bullet world:
//  * the object is a dynamic rigid body with the mass, centre of mass and inertia of its
//    mesh at `density` (geometry/mass_properties; body frame = principal axes at the
//    centre of mass);
//  * the palm (with the knuckles, i.e. the spread is frozen) is a kinematic body that
//    follows a scripted trajectory;
//  * every phalanx is a dynamic body (mass `link_mass`, centre of mass on its joint axis)
//    hinged to its parent at its joint, starting at the given closed joint angles;
//  * the fingers squeeze as the Barrett BH8 drives them (physics/squeeze_model.hpp): one motor
//    per finger, a velocity servo at `closing_speed` with at most the hand file's torque for the
//    joint it drives (each phalanx's `torque_nm`, the hand's published strength; `finger_torque`
//    > 0 overrides it at every joint) - the proximal, its distal coupled by the hand file's ratio (a rigid
//    transmission: the distal's load is the same motor's) - and the TorqueSwitch breakaway:
//    once the proximal touches the object and stalls (or reaches its limit) it is locked and
//    the motor closes the distal alone. Worm drive: a driven joint never opens by more than
//    `worm_backlash` (its lower limit ratchets up to the largest angle reached minus the
//    backlash; squeeze_model.hpp says why), a coupled one is held by the
//    transmission; the upper limits are the hand file's. There is no travel limit: a finger
//    keeps closing after the object as it moves, as far as its joint limits allow. The palm
//    only translates in the script, which the coupling's two-body form relies on;
//    each phalanx has `link_mass` (80 g) and, about its joint axis, the drive's reflected inertia
//    `drive_inertia` (1e-3 kg m^2: a rotor of 6.4e-8 kg m^2 behind the BH8's 125:1 reduction,
//    J_rotor N^2; the rotor's own figure is not published). Without it a short phalanx is a few
//    1e-5 kg m^2 between a motor and a rigid contact, and the solver's iterations move its impulses
//    too little: a Robotiq 3F fingertip on a fixed plate pressed with 84% of its motor's torque
//    after 100 iterations, 42% after 50 (tests/python/test_lift_strength.py); with it, 100%;
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
// Outcome ("lifted": the object came up with the hand and stayed in it):
//   came up   height_gain (the world height the object's centre of mass gained, end minus start)
//             >= lift_height - success_distance: it rose with the palm, or more (a firm grip
//             may pull the object into the palm while it rises);
//   held      hold_displacement (the distance its centre of mass moved in the palm frame from
//             the end of the lift to the end: through the shake and the hold) < success_distance
//             (2 cm);
//   and the simulation stayed finite. displacement (end vs after the squeeze, in the palm frame)
//   and squeeze_displacement (what the squeeze itself moved) are reported for diagnosis.
// Why not "displacement < 2 cm": with the hand's real strength a firm grip keeps pulling the
// object towards the palm after the squeeze (the fingertips curl over its far edges); such an
// object came up further than the palm but moved more than 2 cm in the palm frame, and the old
// rule counted it as dropped (the torque sweep in BENCHMARKS.md, issue 30).
// The run stops early once the object is lost for good: it lags the palm's rise by more than
// max(5 cm, 2.5 x success_distance), or has moved that far in the palm frame after the lift.
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
// Units: Bullet runs in decimetres (bullet_world.hpp kUnit: lengths and gravity x10, inertia
// and torques x100, masses unchanged - the same motion, and the ~1-2 cm phalanges' contacts far
// steadier than at Bullet's metre-scale absolute tolerances). Inputs and results stay in metres.
// Collision margins are `margin` (0.5 mm) on every shape (Bullet's default 4 cm is meant for
// metre-sized bodies); convex hulls and decomposition pieces are shrunk inwards by the margin
// (btConvexHullComputer's shrink, at most half a piece's inner radius) and boxes keep their
// margin inside, so shape + margin is the true surface (capsules are exact; the tetrahedra are
// not shrunk). Solver: `solver_iterations` (100) per step. The sequential-impulse solver's
// error in the contact and joint impulses is relative to the grip force, and it must be small
// next to the object's weight for friction to hold it: at the hand's real strength (1-2 N m,
// forces of tens of newtons on a 1-2 N object) 20 iterations let firm grips drop objects that
// weak ones hold; 100 keep the held share from falling as the torque rises to 3 N m
// (BENCHMARKS.md, "Lift test at the hand's strength").
// The script's step count ceil(total time / time_step) must be at most kMaxLiftSteps (10
// million): the options are rejected otherwise.
// Speed. Bullet runs a GJK query at every step for every pair of child shapes (a hand link's
// capsule or box, one convex piece of the object) whose bounding boxes overlap; with a finger
// inside a mug that is most of the pairs, nearly all of them apart. With
// `skip_separated_pairs` a pair found apart keeps a separating axis and a lower bound on its
// separation that is updated from the two shapes' motion; while the bound exceeds the
// contact-breaking distance and the pair has no contact point, Bullet's query (which would
// add no point) is skipped (physics/separated_pair_skip.hpp). Same results, faster on concave
// objects (see BENCHMARKS.md).
//
// Trace: run(..., trace_every = k > 0) records every k steps and at the last step the time,
// the object's pose in the palm frame, the joint angles, each finger's driven phalanx and every
// hand-object contact (link, point, normal, normal force): LiftResult::trace.
//
// Files: lift_object (object preparation, per-grasp shape, the object's body), hand_bodies
// (palm, phalanges, hinges, motor, limit and coupling rows), squeeze_model (the per-step
// motor law), lift_script (trajectory, the model's steps, outcome and trace), bullet_world
// (the world, its units and ownership), separated_pair_skip (the narrowphase skip).
//
// Thread safety: LiftTester is immutable after construction; each run builds its own Bullet
// world, so run() may be called from many threads at once.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <optional>

#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp {

/// Most steps a lift test may take (LiftOptions are rejected beyond it).
constexpr long kMaxLiftSteps = 10'000'000;

struct LiftOptions {
  enum class Shape { Auto, ConvexHull, Tetrahedra, Decomposition };
  double mu = 0.5;              // friction between the hand and the object
  double table_mu = 0.5;        // friction between the object and the table
  double density = 1000.0;      // kg/m^3 (mass from the mesh)
  double time_step = 1.0 / 480.0;  // s; see the note on time steps above
  int solver_iterations = 100;
  double solver_residual = 0.0;  // Bullet's m_leastSquaresResidualThreshold (its units): a step's
                                 // iterations end once the residual is below it; 0 = run them all
  // Warm start (Bullet's m_warmstartingFactor: the share of a contact's last impulses a step starts
  // from) and friction directions kept from step to step (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING
  // with SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION): without the cache a contact's two
  // friction directions are rebuilt every step, so its friction impulses start again from 0.
  double warmstart_factor = 0.85;
  bool friction_direction_caching = false;
  double squeeze_time = 0.15;   // s
  double lift_height = 0.10;    // m
  double lift_time = 0.40;      // s
  double shake_amplitude = 0.01;  // m
  double shake_frequency = 3.0;   // Hz
  double shake_time = 0.5;        // s
  double hold_time = 0.1;         // s
  double finger_torque = 0.0;     // N m, > 0: the motors' torque limit at every driven joint; 0: the hand file's (torque_nm)
  double closing_speed = 1.0;     // rad/s, the motor's target velocity (closing)
  double worm_backlash = 0.01;    // rad a driven or locked joint may open below the largest angle it reached (squeeze_model.hpp)
  double link_mass = 0.08;        // kg per phalanx
  double drive_inertia = 1e-3;    // kg m^2 added to each phalanx about its joint axis (the drive's reflected inertia)
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

/// Throws std::invalid_argument naming the first bad field (and a script of no or too many steps).
void validate(const LiftOptions& options);

/// Throws std::invalid_argument unless volume and mass are > 0, com finite and inertia finite,
/// symmetric and positive semi-definite (given mass properties of a lift-test object).
void validate(const MassProperties& mass);

/// One contact between a hand link and the object in a traced step (world frame).
struct LiftContact {
  int sample = 0;            // index of the traced step
  int link = 0;              // HandModel link index (0: palm and knuckles)
  Vec3 point = Vec3::Zero(); // m, on the hand link's surface
  Vec3 normal = Vec3::Zero();// unit, out of the object (towards the hand)
  double force = 0.0;        // N, normal force in that step
};

/// Per-step trace of one lift test, every `every` steps and at the last step simulated.
struct LiftTrace {
  int every = 0;
  std::vector<std::string> link_names;  // HandModel link names
  Eigen::Vector3d phase_ends = Eigen::Vector3d::Zero();  // s: end of the squeeze, the lift, the shake
  Iso3 reference_pose = Iso3::Identity();  // the object (centre of mass, principal axes) in the palm frame after the squeeze
  std::vector<double> time;         // s, per sample
  std::vector<Iso3> object_pose;    // per sample: the object in the palm frame
  std::vector<Eigen::VectorXd> joints;     // per sample: joint angles (HandModel layout)
  std::vector<Eigen::VectorXi> driven;     // per sample: the phalanx each finger's motor drives
  std::vector<LiftContact> contacts;
};

struct LiftResult {
  bool lifted = false;
  double displacement = 0.0;  // m, object's centre of mass relative to the palm, end vs after the squeeze
  double hold_displacement = 0.0;  // m, the same, end vs the end of the lift (the shake and the hold)
  double rotation = 0.0;      // rad, object's rotation relative to the palm, end vs after the squeeze
  double squeeze_displacement = 0.0;  // m, how far the squeeze itself moved the object (in the palm frame)
  double height_gain = 0.0;   // m, world z of the object's centre of mass, end minus start
  bool finite = true;         // false if the simulation blew up (then lifted = false)
  bool tetrahedra = false;    // the object used the tetrahedra shape
  LiftOptions::Shape shape = LiftOptions::Shape::ConvexHull;  // the shape used (never Auto)
  int steps = 0;
  long skipped_queries = 0;  // narrowphase queries skipped (LiftOptions::skip_separated_pairs)
  Eigen::VectorXi breakaway;  // per finger: the phalanx its motor drives at the end (0: no breakaway)
  std::shared_ptr<LiftTrace> trace;  // the per-step trace when asked for (run's trace_every > 0)
};


class LiftTester {
 public:
  /// `object` in the world frame (the frame of the hand poses). `convex_pieces`: optional
  /// approximate convex decomposition of the object (world frame, one (K, 3) point set per
  /// piece; each piece's convex hull is used), needed by Shape::Decomposition and used by
  /// Auto for concave objects. Throws std::invalid_argument for a bad mesh, a mesh
  /// enclosing no volume, bad options, a piece that is not finite or spans no volume, or a hand
  /// without a torque for some phalanx (torque_nm) when options.finger_torque is 0.
  /// `mass`: the object's mass properties (world frame) when the caller knows them better than
  /// the mesh's closed-surface integral at options.density does (an open scan, a weighed
  /// object); checked by validate(MassProperties). None: computed from the mesh.
  LiftTester(const HandModel& hand, const TriMesh& object, const LiftOptions& options = {},
             const std::vector<Eigen::MatrixX3d>& convex_pieces = {},
             const std::optional<MassProperties>& mass = std::nullopt);
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
  /// `trace_every` > 0: the result carries a trace of every trace_every-th step (0: none).
  LiftResult run(const Iso3& hand_pose, const Eigen::VectorXd& joints, int trace_every = 0) const;

  /// The shape each grasp's lift test would use (row i of `joints` with poses[i]; no simulation):
  /// under Auto on a concave object, ConvexHull unless a hand link reaches into the hull. Lets a
  /// caller postpone a concave object's decomposition until a grasp needs it. Throws as run_batch.
  std::vector<LiftOptions::Shape> shapes(const std::vector<Iso3>& poses,
                                         const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints) const;

  /// N lift tests (row i of `joints` with poses[i]) in `threads` threads (0 = all cores,
  /// common/parallel.hpp thread_count; negative is an error), each with its own Bullet
  /// world. Results in input order, identical to run() one by one.
  std::vector<LiftResult> run_batch(const std::vector<Iso3>& poses,
                                    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints,
                                    int threads = 1) const;

  struct Impl;

 private:
  LiftResult simulate(const Iso3& hand_pose, const Eigen::VectorXd& joints, LiftTrace* trace) const;  // validated input
  void check_batch(const std::vector<Iso3>& poses,
                   const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& joints) const;
  std::unique_ptr<Impl> impl_;
};

/// One-shot convenience: LiftTester(hand, object, options).run(hand_pose, joints).
LiftResult lift_test(const HandModel& hand, const Iso3& hand_pose, const Eigen::VectorXd& joints,
                     const TriMesh& object, const LiftOptions& options = {});

}  // namespace bayesgrasp
