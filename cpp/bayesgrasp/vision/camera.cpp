#include "bayesgrasp/vision/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "bayesgrasp/common/checks.hpp"
#include "bayesgrasp/common/random.hpp"

namespace bayesgrasp::vision {

void validate(const Intrinsics& K) {
  require_at_least(K.width, 1, "width");
  require_at_least(K.height, 1, "height");
  if (static_cast<long long>(K.width) * K.height > 50'000'000)
    throw std::invalid_argument("width * height: image too large");
  require_positive(K.fx, "fx");
  require_positive(K.fy, "fy");
  require_finite(K.cx, "cx");
  require_finite(K.cy, "cy");
}

void validate(const Table& t) {
  require_finite(t.z, "z");
  require_finite(t.center_x, "center_x");
  require_finite(t.center_y, "center_y");
  if (!(t.half_x > 0)) bad_field("half_x", "positive (inf allowed)", number_str(t.half_x));
  if (!(t.half_y > 0)) bad_field("half_y", "positive (inf allowed)", number_str(t.half_y));
}

void validate(const NoiseModel& n) {
  require_non_negative(n.sigma_a, "sigma_a");
  require_non_negative(n.sigma_b, "sigma_b");
  require_finite(n.sigma_z0, "sigma_z0");
  require_positive(n.baseline, "baseline");
  require_non_negative(n.disparity_step, "disparity_step");
  require_finite(n.max_incidence, "max_incidence");
  require_positive(n.edge_jump, "edge_jump");
  require_in(n.edge_drop_prob, 0, 1, "edge_drop_prob");
  require_finite(n.min_depth, "min_depth");
  require_positive(n.max_depth, "max_depth");
}

Iso3 look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  if (!eye.allFinite() || !target.allFinite() || !up.allFinite())
    throw std::invalid_argument("look_at: eye, target and up must be finite");
  const Vec3 dir = target - eye;
  if (dir.norm() < 1e-12) throw std::invalid_argument("look_at: eye and target coincide");
  const Vec3 z = dir.normalized();
  const Vec3 xr = z.cross(up);
  if (xr.norm() < 1e-9 * std::max(1.0, up.norm()))
    throw std::invalid_argument("look_at: viewing direction is parallel to up");
  const Vec3 x = xr.normalized();
  const Vec3 y = z.cross(x);  // image down
  Iso3 T = Iso3::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

// ---------------------------------------------------------------------------------------
// BVH: nodes with an axis-aligned box; leaves hold a contiguous range of triangles.
struct RayCaster::Impl {
  struct Tri {
    Vec3 v0, e1, e2, n;
    int mesh, face;
  };
  struct Node {
    Eigen::Vector3d lo, hi;
    int left = -1;   // index of the first child (second is left + 1) if inner
    int start = 0, count = 0;  // leaf range in tris
  };
  std::vector<Tri> tris;
  std::vector<Node> nodes;

  // Fills node `id` for tris[start, start + count) (median split on the longest centroid axis).
  void build(int id, int start, int count, std::vector<Vec3>& cent) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    Vec3 clo = lo, chi = hi;
    for (int i = start; i < start + count; ++i) {
      const Tri& t = tris[i];
      for (const Vec3& p : {t.v0, Vec3(t.v0 + t.e1), Vec3(t.v0 + t.e2)}) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      clo = clo.cwiseMin(cent[i]);
      chi = chi.cwiseMax(cent[i]);
    }
    nodes[id].lo = lo;
    nodes[id].hi = hi;
    if (count <= 4) {
      nodes[id].start = start;
      nodes[id].count = count;
      return;
    }
    int axis;
    (chi - clo).maxCoeff(&axis);
    const int half = count / 2;
    std::vector<int> idx(count);
    std::iota(idx.begin(), idx.end(), start);
    std::nth_element(idx.begin(), idx.begin() + half, idx.end(),
                     [&](int a, int b) { return cent[a][axis] < cent[b][axis]; });
    std::vector<Tri> tt(count);
    std::vector<Vec3> cc(count);
    for (int i = 0; i < count; ++i) {
      tt[i] = tris[idx[i]];
      cc[i] = cent[idx[i]];
    }
    std::copy(tt.begin(), tt.end(), tris.begin() + start);
    std::copy(cc.begin(), cc.end(), cent.begin() + start);
    const int left = static_cast<int>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[id].left = left;
    build(left, start, half, cent);
    build(left + 1, start + half, count - half, cent);
  }
};

RayCaster::RayCaster(const std::vector<TriMesh>& meshes) : impl_(std::make_unique<Impl>()) {
  std::vector<Vec3> cent;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    validate_mesh(meshes[m]);
    const TriMesh& M = meshes[m];
    for (Eigen::Index f = 0; f < M.F.rows(); ++f) {
      Impl::Tri t;
      t.v0 = M.V.row(M.F(f, 0)).transpose();
      const Vec3 v1 = M.V.row(M.F(f, 1)).transpose(), v2 = M.V.row(M.F(f, 2)).transpose();
      t.e1 = v1 - t.v0;
      t.e2 = v2 - t.v0;
      const Vec3 n = t.e1.cross(t.e2);
      if (!(n.norm() > 0)) continue;  // degenerate triangles are invisible
      t.n = n.normalized();
      t.mesh = static_cast<int>(m);
      t.face = static_cast<int>(f);
      impl_->tris.push_back(t);
      cent.push_back(t.v0 + (t.e1 + t.e2) / 3.0);
    }
  }
  if (!impl_->tris.empty()) {
    impl_->nodes.reserve(2 * impl_->tris.size() + 1);
    impl_->nodes.emplace_back();
    impl_->build(0, 0, static_cast<int>(impl_->tris.size()), cent);
  }
}
RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;
std::size_t RayCaster::num_triangles() const { return impl_->tris.size(); }

bool RayCaster::intersect(const Vec3& o, const Vec3& d, Hit& hit, double tmin, double tmax) const {
  const auto& nodes = impl_->nodes;
  const auto& tris = impl_->tris;
  if (nodes.empty()) return false;
  const Vec3 inv(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
  double best = tmax;
  int best_i = -1;
  auto box_hit = [&](const Impl::Node& n, double& tnear) {
    double t0 = tmin, t1 = best;
    for (int a = 0; a < 3; ++a) {
      double ta = (n.lo[a] - o[a]) * inv[a], tb = (n.hi[a] - o[a]) * inv[a];
      if (ta > tb) std::swap(ta, tb);
      if (std::isnan(ta) || std::isnan(tb)) {  // ray parallel and on the slab boundary
        if (o[a] < n.lo[a] || o[a] > n.hi[a]) return false;
        continue;
      }
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    tnear = t0;
    return true;
  };
  int stack[128];
  int sp = 0;
  double tn = 0;
  if (!box_hit(nodes[0], tn)) return false;
  stack[sp++] = 0;
  while (sp > 0) {
    const Impl::Node& n = nodes[stack[--sp]];
    if (n.left < 0) {
      for (int i = n.start; i < n.start + n.count; ++i) {
        const Impl::Tri& t = tris[i];
        // Moeller-Trumbore.
        const Vec3 p = d.cross(t.e2);
        const double det = t.e1.dot(p);
        if (std::abs(det) < 1e-300) continue;
        const double id = 1.0 / det;
        const Vec3 s = o - t.v0;
        const double u = s.dot(p) * id;
        if (u < 0.0 || u > 1.0) continue;
        const Vec3 q = s.cross(t.e1);
        const double v = d.dot(q) * id;
        if (v < 0.0 || u + v > 1.0) continue;
        const double tt = t.e2.dot(q) * id;
        if (tt > tmin && tt < best) {
          best = tt;
          best_i = i;
        }
      }
      continue;
    }
    double ta = 0, tb = 0;
    const bool ha = box_hit(nodes[n.left], ta), hb = box_hit(nodes[n.left + 1], tb);
    if (ha && hb) {
      // Push the farther first so the nearer is visited first.
      if (ta < tb) {
        stack[sp++] = n.left + 1;
        stack[sp++] = n.left;
      } else {
        stack[sp++] = n.left;
        stack[sp++] = n.left + 1;
      }
    } else if (ha) {
      stack[sp++] = n.left;
    } else if (hb) {
      stack[sp++] = n.left + 1;
    }
  }
  if (best_i < 0) return false;
  hit.t = best;
  hit.normal = tris[best_i].n;
  hit.mesh = tris[best_i].mesh;
  hit.face = tris[best_i].face;
  return true;
}

// ---------------------------------------------------------------------------------------
RenderResult render(const Intrinsics& K, const Iso3& pose, const std::vector<TriMesh>& meshes,
                    const Table& table, const NoiseModel& noise) {
  const RayCaster caster(meshes);
  return render(K, pose, caster, table, noise);
}

namespace {
// Uniform in (0, 1) from (seed, pixel, stream).
double uniform(std::uint64_t seed, std::uint64_t pixel, std::uint64_t stream) {
  const std::uint64_t h = mix_seed(mix_seed(seed ^ 0x5851F42D4C957F2Dull) ^ (pixel * 4 + stream));
  return (static_cast<double>(h >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

// Noise-free depth, labels and |cos| of the incidence angle per pixel: the nearest of the meshes'
// hits and the table rectangle.
void cast_rays(const Intrinsics& K, const Iso3& pose, const RayCaster& caster, const Table& table, RenderResult& out,
               DepthImage& cosang) {
  const int W = K.width, H = K.height;
  const Mat3 R = pose.linear();
  const Vec3 o = pose.translation();
#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Vec3 dc((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const Vec3 d = R * dc;  // t along d equals camera-frame depth
      RayCaster::Hit hit;
      double best = std::numeric_limits<double>::infinity();
      int label = -1;
      Vec3 n = Vec3::Zero();
      if (caster.intersect(o, d, hit)) {
        best = hit.t;
        label = hit.mesh;
        n = hit.normal;
      }
      if (table.enabled && std::abs(d.z()) > 1e-15) {
        const double t = (table.z - o.z()) / d.z();
        if (t > 0 && t < best) {
          const Vec3 p = o + t * d;
          if (std::abs(p.x() - table.center_x) <= table.half_x && std::abs(p.y() - table.center_y) <= table.half_y) {
            best = t;
            label = -2;
            n = Vec3::UnitZ();
          }
        }
      }
      if (label != -1) {
        out.depth(v, u) = best;
        out.label(v, u) = label;
        cosang(v, u) = std::abs(n.dot(d)) / d.norm();
      }
    }
  }
}

// The noise model on a noise-free depth image: dropping (incidence, edges, range) is decided on
// the noise-free image, then axial noise and disparity quantisation are applied.
void add_noise(const Intrinsics& K, const NoiseModel& noise, const DepthImage& cosang, DepthImage& depth) {
  const int W = K.width, H = K.height;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const DepthImage clean = depth;
  const double cos_max = std::cos(noise.max_incidence);
  const double fB = K.fx * noise.baseline;
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const double z = clean(v, u);
      if (std::isnan(z)) continue;
      const std::uint64_t pix = static_cast<std::uint64_t>(v) * W + u;
      bool drop = z < noise.min_depth || z > noise.max_depth || cosang(v, u) < cos_max;
      if (!drop && noise.edge_drop_prob > 0) {
        bool edge = false;
        const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4 && !edge; ++k) {
          const int uu = u + du[k], vv = v + dv[k];
          if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
          const double zn = clean(vv, uu);
          edge = std::isnan(zn) || zn < z - noise.edge_jump;
        }
        if (edge && uniform(noise.seed, pix, 0) < noise.edge_drop_prob) drop = true;
      }
      if (drop) {
        depth(v, u) = nan;
        continue;
      }
      const double sigma = noise.sigma_a + noise.sigma_b * (z - noise.sigma_z0) * (z - noise.sigma_z0);
      const double u1 = uniform(noise.seed, pix, 1), u2 = uniform(noise.seed, pix, 2);
      const double g = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
      double zn = z + sigma * g;
      if (noise.disparity_step > 0 && zn > 0) {
        const double disp = fB / zn;
        const double q = std::round(disp / noise.disparity_step) * noise.disparity_step;
        zn = q > 0 ? fB / q : nan;
      }
      depth(v, u) = zn;
    }
  }
}
}  // namespace

RenderResult render(const Intrinsics& K, const Iso3& pose, const RayCaster& caster, const Table& table,
                    const NoiseModel& noise) {
  validate(K);
  validate(table);
  validate(noise);
  if (!pose.matrix().allFinite()) throw std::invalid_argument("camera pose must be finite");
  RenderResult out;
  out.depth = DepthImage::Constant(K.height, K.width, std::numeric_limits<double>::quiet_NaN());
  out.label = decltype(out.label)::Constant(K.height, K.width, -1);
  DepthImage cosang = DepthImage::Zero(K.height, K.width);
  cast_rays(K, pose, caster, table, out, cosang);
  if (noise.enabled) add_noise(K, noise, cosang, out.depth);
  return out;
}

Points depth_to_points(const Intrinsics& K, const DepthImage& depth, const Iso3& pose, bool world,
                       bool organised) {
  validate(K);
  if (depth.rows() != K.height || depth.cols() != K.width)
    throw std::invalid_argument("depth image size does not match the intrinsics");
  const int H = K.height, W = K.width;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Index n = 0;
  if (!organised) {
    for (Eigen::Index i = 0; i < depth.size(); ++i) n += std::isfinite(depth.data()[i]) && depth.data()[i] > 0;
  } else {
    n = static_cast<Eigen::Index>(H) * W;
  }
  Points P(n, 3);
  Eigen::Index k = 0;
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const double z = depth(v, u);
      const bool ok = std::isfinite(z) && z > 0;
      if (!ok) {
        if (organised) P.row(k++).setConstant(nan);
        continue;
      }
      Vec3 p((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
      if (world) p = pose * p;
      P.row(k++) = p.transpose();
    }
  }
  return P;
}

}  // namespace bayesgrasp::vision
