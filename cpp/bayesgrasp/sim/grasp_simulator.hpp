// Contact simulation: a hand (HandModel) closing on a static triangle-mesh object standing on
// an optional infinite table (z = 0), with FCL distance queries.
//
// Closing (auto-grasp; sim/closing.cpp). Every finger starts at its open preshape (actuator
// t = 0) and closes by conservative advancement: with d the distance between the moving links
// and the obstacles and v an upper bound on how fast any point of those links moves per unit of
// t (sim/finger_motion.hpp), the step dt = (d - tol / 2) / v can never make a link penetrate.
// Steps repeat until a link is within `contact_tolerance` of the object or the table; then the
// breakaway rule of HandModel applies (the touching phalanx and all earlier ones of its finger
// freeze, the later ones keep closing; a phalanx reaching its upper limit stops alone). Each
// finger advances independently (fingers do not collide with each other). A link within the
// tolerance whose motion is not clearly into the obstacle (e.g. a capsule resting on a rim and
// rotating along it) is not stopped: it advances by trial steps of 2 mm of travel, checked by a
// distance query and refined by bisection when blocked (GraspIt!-style), so that only
// approaching contacts stop a phalanx.
//
// Distances (sim/distance_bounds.hpp, sim/distance_queries.hpp). Cheap lower bounds replace
// FCL queries when they exceed `box_skip`: the gap between the link's and the object's
// axis-aligned boxes and the separating-axis bound over the object's 26-DOP; fingers whose
// whole reach cannot touch the object only see the table (closed form). FCL geometry: the
// object is a BVHModel<OBBRSS> (or RSS); by default each capsule is its axis as a sliver
// triangle (FCL's analytic triangle-triangle distance, radius subtracted) and boxes are
// 12-triangle meshes, which is faster than FCL's capsule/box primitives (GJK per triangle; see
// BENCHMARKS.md). Query pruning (sim/query_pruning.hpp) skips the queries whose answer cannot
// change the step or the contacts.
//
// Approaches (sim/approach.hpp): the open hand, oriented by the approach direction d (hand +z)
// and a roll about it (HandModel::approach_pose), starts on the line through a target point,
// clear of the object and the table, and moves along d by conservative advancement until any
// link is within the tolerance of the object or of a table it moves towards; it then backs off
// by `standoff` along d and closes. Top grasps are the approach along d = -z with roll = yaw.
// Along d = -z with a table (and only then), the palm is also kept at least `table_clearance`
// above the deepest point the closing fingers sweep, so that on an object lower than the
// fingers are long the fingers wrap it near its base instead of striking the table.
//
// Thread safety: all queries are const and keep their state on the stack, so one simulator
// can serve many threads (FCL's BVH model is only read by distance queries).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "bayesgrasp/geometry/contact.hpp"
#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/hand/hand_model.hpp"

namespace bayesgrasp {

struct SimOptions {
  bool table = true;                // infinite table plane at z = 0
  double contact_tolerance = 2e-4;  // a link touches when closer than this (m)
  /// Error allowance of the advancing distance queries, relative to the link's box distance
  /// to the object (the step subtracts it, so it stays conservative). Final contact queries
  /// are exact.
  double rel_err = 0.0;
  /// Triangle pairs whose distances to a link differ by less than this (m) count as tied: an FCL
  /// query keeps the first one it finds and prunes the rest (sim/bvh_distance.hpp). A link
  /// parallel to a finely tessellated face otherwise visits every triangle under it. 0 = FCL's
  /// own traversal.
  double tie_tolerance = 1e-12;
  /// Links whose lower bound on the object distance (box gap, 26-DOP separating axes) exceeds
  /// this use that bound instead of an FCL query (must exceed contact_tolerance).
  double box_skip = 5e-4;
  enum class Bv { OBBRSS, RSS };
  Bv bv = Bv::OBBRSS;
  /// Link geometry for FCL distance queries: Segments = each capsule's axis as a sliver
  /// triangle (FCL's analytic triangle-triangle distance; the radius is subtracted) and boxes
  /// as 12-triangle meshes; Primitives = FCL capsules/boxes (GJK per triangle); Meshes =
  /// tessellated capsules circumscribing the real ones. Boolean checks always use primitives.
  enum class LinkGeometry { Segments, Primitives, Meshes };
  LinkGeometry links = LinkGeometry::Segments;
  int max_iterations = 5000;  // per finger and per approach (a safety net), >= 1
  /// Approaches along -z (top grasps) with a table: minimum height of the fingers' closing
  /// sweep above the table (m); negative disables the rule (the hand then stops at the first
  /// contact).
  double table_clearance = 0.005;
  /// Skip FCL queries whose answer cannot change the result (same joint angles and contacts up
  /// to round-off; see sim/query_pruning.hpp): lower bounds carried between advancement steps,
  /// and queries capped at the only distance that matters. false = one query per link near the
  /// object and step (for tests and benchmarks). Only applies with rel_err = 0.
  bool prune_queries = true;
};

/// Throws std::invalid_argument naming the first option out of range.
void validate(const SimOptions& options);

/// One approach (world frame; see GraspSimulator::approach).
struct ApproachSpec {
  Vec3 direction = -Vec3::UnitZ();  // direction of motion = hand +z (normalised by the simulator)
  double roll = 0.0;                // rad, about -direction (HandModel::approach_pose)
  Vec3 target = Vec3::Zero();       // a point on the palm centre's line of motion (m)
};

struct GraspResult {
  Eigen::VectorXd joints;           // HandModel layout
  Contacts contacts;                // at most one object and one table contact per link
  std::vector<uint8_t> link_contact;   // per link: touches the object
  std::vector<uint8_t> table_contact;  // per link: touches the table
  bool collision_at_start = false;  // the open hand penetrated the object or the table
  bool stopped_by_table = false;    // an approach stopped on the table without touching the object
  Iso3 hand_pose = Iso3::Identity();
  // statistics
  int distance_queries = 0;  // FCL distance calls
  int iterations = 0;        // advancement steps (all fingers + approach)
};

/// N results as flat arrays (row i = grasp i); contacts of grasp i are
/// contacts[offsets[i] .. offsets[i+1]).
struct GraspBatch {
  int num_grasps = 0, num_joints = 0, num_links = 0;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> joints;          // N x J
  Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> link_contact;   // N x L
  Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> table_contact;  // N x L
  std::vector<uint8_t> collision_at_start;  // N
  std::vector<uint8_t> stopped_by_table;    // N
  std::vector<Iso3> hand_poses;             // N
  Contacts contacts;                        // concatenated
  std::vector<int64_t> offsets;             // N + 1
  std::vector<int> distance_queries;        // N
};

namespace sim {
struct SimScene;
}

class GraspSimulator {
 public:
  /// `object` is in the world frame and static; throws std::invalid_argument for a bad mesh
  /// or an option out of range (naming it).
  GraspSimulator(const HandModel& hand, const TriMesh& object, const SimOptions& options = {});
  ~GraspSimulator();
  GraspSimulator(GraspSimulator&&) noexcept;
  GraspSimulator& operator=(GraspSimulator&&) noexcept;

  const HandModel& hand() const;
  const TriMesh& object() const;
  const SimOptions& options() const;

  /// Auto-grasp from `hand_pose` (world) with the given spread. Throws std::invalid_argument
  /// for a non-finite pose or a spread outside the hand's limits.
  GraspResult close(const Iso3& hand_pose, double spread) const;

  /// Approach, then auto-grasp. The open hand (preshape `spread`) at
  /// HandModel::approach_pose(direction, roll, .) starts on the line through `target` along the
  /// direction, 1 cm before the object's bounding box (its deepest point along the direction
  /// behind the box's nearest corner), and, if the direction descends, at least 5 mm above the
  /// table; it moves along the direction until a link is within the contact tolerance of the
  /// object or of the table (only when moving down onto it), backs off by `standoff` (>= 0, m)
  /// along the direction and closes. It gives up (and closes where it is) once the palm has
  /// passed the object's box by half the open hand's depth (descending onto a table: by 1 m
  /// more) without a contact. d = -z keeps
  /// the table-clearance rule of top grasps. A start in collision (the open hand in the table)
  /// is reported (collision_at_start), not an error. Throws std::invalid_argument naming
  /// `direction` (zero or not finite), `roll`, `target` (not finite, or below a table), `spread`
  /// or `standoff`.
  GraspResult approach(const ApproachSpec& approach, double spread, double standoff = 0.0) const;

  /// Palm-down approach at (x, y, yaw): approach({-z, yaw, (x, y, 0)}, spread, standoff).
  GraspResult top_grasp(double x, double y, double yaw, double spread, double standoff = 0.0) const;

  /// The same auto-grasp done GraspIt!-style: the actuator advances in fixed steps of `step`
  /// rad with a boolean collision check (FCL) after each; on a collision the contact is
  /// located by bisection to `contact_tolerance` of link travel. For comparison only.
  GraspResult close_fixed_step(const Iso3& hand_pose, double spread, double step = 0.01) const;

  /// Batches in `threads` threads (0 = all cores, see common/parallel.hpp thread_count;
  /// negative is an error). Results in input order, the same for any thread count.
  GraspBatch close_batch(const std::vector<Iso3>& poses, const std::vector<double>& spreads,
                         int threads = 1) const;
  /// xyyaw: N x 3 rows (x, y, yaw).
  GraspBatch top_grasp_batch(const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& xyyaw,
                             double spread, double standoff = 0.0, int threads = 1) const;
  /// approach() for each entry; errors name the entry (`directions[i]`, `targets[i]`, `rolls[i]`).
  GraspBatch approach_batch(const std::vector<ApproachSpec>& approaches, double spread, double standoff = 0.0,
                            int threads = 1) const;

  /// Exact distance from link `link` at joint vector q (hand at hand_pose) to the object
  /// (ignores the table); negative if penetrating. For tests and diagnostics.
  double link_object_distance(const Iso3& hand_pose, const Eigen::VectorXd& q, int link) const;

  /// The prepared geometry the steps in sim/*.hpp work on (for tests and new steps).
  const sim::SimScene& scene() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Fills `batch` row i from `r` (used by the batch calls; exposed for the bindings).
GraspBatch make_batch(const std::vector<GraspResult>& results, int num_joints, int num_links);

}  // namespace bayesgrasp
