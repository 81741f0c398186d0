// What every simulation step reads: the hand, the object and its query geometry, the options.
// Built once by GraspSimulator and immutable afterwards (so the steps may run in many threads).
#pragma once

#include <vector>

#include "bayesgrasp/hand/hand_model.hpp"
#include "bayesgrasp/sim/finger_motion.hpp"
#include "bayesgrasp/sim/grasp_simulator.hpp"
#include "bayesgrasp/sim/link_geometry.hpp"

namespace bayesgrasp::sim {

struct SimScene {
  HandModel hand;
  TriMesh mesh;
  SimOptions options;
  ObjectGeometry object;
  LinkShapes links;
  std::vector<FingerMotion> fingers;
  /// Deepest point below the palm face reached by the closing fingers (see approach.hpp).
  double sweep_depth = 0.0;

  /// Whether query pruning applies (SimOptions::prune_queries; a bit mask holds the links).
  bool pruning() const { return options.prune_queries && options.rel_err == 0.0 && hand.num_links() <= 64; }
};

/// Validates the mesh and the options and prepares the geometry.
SimScene make_scene(const HandModel& hand, const TriMesh& object, const SimOptions& options);

}  // namespace bayesgrasp::sim
