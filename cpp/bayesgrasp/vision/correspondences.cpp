#include "bayesgrasp/vision/correspondences.hpp"

#include <algorithm>
#include <limits>

namespace bayesgrasp::vision {

MatchDescriptors match_descriptors(const Features& features, bool hellinger) {
  MatchDescriptors d;
  d.f = features;
  if (hellinger) d.f = d.f.cwiseMax(0.f).cwiseSqrt();
  d.sq_norm = d.f.rowwise().squaredNorm();
  return d;
}

namespace {
// Inserts (j, dj) into the k best so far, kept sorted by distance (ties: the earlier first).
void keep_nearest(int j, float dj, int k, int& count, std::vector<int>& top_i, std::vector<float>& top_d) {
  if (count == k && !(dj < top_d[count - 1])) return;
  int pos = count < k ? count++ : k - 1;
  while (pos > 0 && top_d[pos - 1] > dj) {
    top_d[pos] = top_d[pos - 1];
    top_i[pos] = top_i[pos - 1];
    --pos;
  }
  top_d[pos] = dj;
  top_i[pos] = j;
}
}  // namespace

Correspondences correspondences(const MatchDescriptors& scene, const MatchDescriptors& model,
                                const CorrespondenceOptions& options) {
  const int ns = scene.size(), nm = model.size();
  const int k = std::min(options.neighbours, nm);
  Correspondences corr;
  corr.reserve(static_cast<std::size_t>(ns) * k + nm);
  // Squared distances up to a per-column constant, a block of scene descriptors at a time.
  const int block = 256;
  Eigen::MatrixXf D;
  std::vector<int> top_i(k);
  std::vector<float> top_d(k);
  std::vector<float> rbest(nm, std::numeric_limits<float>::infinity());
  std::vector<int> rarg(nm, -1);
  for (int s0 = 0; s0 < ns; s0 += block) {
    const int bs = std::min(block, ns - s0);
    // Column i: -2 <model descriptors, scene descriptor s0 + i>, contiguous for the scans below.
    D.noalias() = -2.0f * model.f * scene.f.middleRows(s0, bs).transpose();
    for (int i = 0; i < bs; ++i) {
      const float* col = D.col(i).data();
      const float sn = scene.sq_norm(s0 + i);
      int count = 0;
      for (int j = 0; j < nm; ++j) {
        keep_nearest(j, col[j] + model.sq_norm(j), k, count, top_i, top_d);
        if (options.reverse && col[j] + sn < rbest[j]) {
          rbest[j] = col[j] + sn;
          rarg[j] = s0 + i;
        }
      }
      for (int j = 0; j < count; ++j) corr.emplace_back(s0 + i, top_i[j]);
    }
  }
  if (options.reverse)
    for (int j = 0; j < nm; ++j)
      if (rarg[j] >= 0) corr.emplace_back(rarg[j], j);
  return corr;
}

}  // namespace bayesgrasp::vision
