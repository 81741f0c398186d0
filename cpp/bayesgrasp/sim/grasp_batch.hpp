// Many grasps of one simulator in threads (the batch calls of GraspSimulator).
#pragma once

#include <functional>

#include "bayesgrasp/sim/sim_scene.hpp"

namespace bayesgrasp::sim {

/// grasp(i) for i in [0, n) in `threads` threads (common/parallel.hpp thread_count: 0 = all
/// cores, negative is an error), gathered by make_batch in input order.
GraspBatch grasp_batch(const SimScene& s, int n, int threads, const std::function<GraspResult(int)>& grasp);

}  // namespace bayesgrasp::sim
