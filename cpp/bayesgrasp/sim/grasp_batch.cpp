// Batches: many grasps in threads, gathered into flat arrays (GraspBatch).
#include "bayesgrasp/sim/grasp_batch.hpp"

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp {

GraspBatch make_batch(const std::vector<GraspResult>& results, int J, int L) {
  GraspBatch b;
  const int N = static_cast<int>(results.size());
  b.num_grasps = N, b.num_joints = J, b.num_links = L;
  b.joints.resize(N, J);
  b.link_contact.setZero(N, L);
  b.table_contact.setZero(N, L);
  b.collision_at_start.resize(N);
  b.stopped_by_table.resize(N);
  b.hand_poses.resize(N);
  b.offsets.assign(N + 1, 0);
  b.distance_queries.resize(N);
  for (int i = 0; i < N; ++i) b.offsets[i + 1] = b.offsets[i] + static_cast<int64_t>(results[i].contacts.size());
  b.contacts.reserve(b.offsets[N]);
  for (int i = 0; i < N; ++i) {
    const GraspResult& r = results[i];
    b.joints.row(i) = r.joints.transpose();
    for (int l = 0; l < L && l < static_cast<int>(r.link_contact.size()); ++l) {
      b.link_contact(i, l) = r.link_contact[l];
      b.table_contact(i, l) = r.table_contact[l];
    }
    b.collision_at_start[i] = r.collision_at_start;
    b.stopped_by_table[i] = r.stopped_by_table;
    b.hand_poses[i] = r.hand_pose;
    b.distance_queries[i] = r.distance_queries;
    b.contacts.insert(b.contacts.end(), r.contacts.begin(), r.contacts.end());
  }
  return b;
}

namespace sim {

GraspBatch grasp_batch(const SimScene& s, int n, int threads, const std::function<GraspResult(int)>& grasp) {
  const std::vector<GraspResult> results = parallel_map<GraspResult>(n, threads, 4, [&](long i) {
    return grasp(static_cast<int>(i));
  });
  return make_batch(results, s.hand.num_joints(), s.hand.num_links());
}

}  // namespace sim

}  // namespace bayesgrasp
