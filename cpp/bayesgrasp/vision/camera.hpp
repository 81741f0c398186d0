// Simulated depth camera: a pinhole camera that ray casts triangle meshes (and an optional
// table rectangle) through a compact BVH, with a structured-light (Kinect-v1-like) noise model,
// and back-projection of depth images to point clouds. No PCL here (this header is light).
//
// Frames: the camera frame is the computer-vision one (x right, y down, z forward); `pose`
// maps camera coordinates to world coordinates (z up, table top at z = 0 by default).
// Depth is the z coordinate in the camera frame (not the ray length); missing pixels are NaN.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp::vision {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using DepthImage = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Pinhole intrinsics in pixels. Pixel (u, v) (column, row) has its centre at (u, v);
/// the principal point of the default is the image centre ((W-1)/2, (H-1)/2).
struct Intrinsics {
  int width = 640;
  int height = 480;
  double fx = 525.0;
  double fy = 525.0;
  double cx = 319.5;
  double cy = 239.5;
};

/// Throws std::invalid_argument if sizes are not positive or the focal lengths are not
/// positive and finite.
/// Each throws std::invalid_argument naming the first bad field.
void validate(const Intrinsics& K);

/// Camera-to-world pose looking from `eye` at `target`, with image "up" (-y_cam) as close
/// as possible to `up`. Throws if eye == target or the view direction is parallel to `up`.
Iso3 look_at(const Vec3& eye, const Vec3& target, const Vec3& up = Vec3::UnitZ());

/// A rectangular table top at height z, centred at (cx, cy), half extents hx, hy (may be
/// +infinity for an infinite plane). Seen from both sides.
struct Table {
  bool enabled = false;
  double z = 0.0;
  double center_x = 0.0, center_y = 0.0;
  double half_x = 0.5, half_y = 0.5;
};
void validate(const Table& table);

/// Structured-light noise (defaults: Kinect v1). All effects are switched off by `enabled = false`.
///  - axial noise: Gaussian, sigma(z) = sigma_a + sigma_b (z - sigma_z0)^2 (Nguyen et al. 2012);
///  - quantisation of disparity d = f B / z in steps of `disparity_step` pixels;
///  - pixels whose incidence angle (between the ray and the surface normal) exceeds
///    `max_incidence` radians are dropped;
///  - pixels on the far side of a depth discontinuity larger than `edge_jump` metres (or next
///    to a pixel that sees nothing) are dropped with probability `edge_drop_prob`.
/// Randomness comes from `seed` through a counter-based generator (same seed, same image,
/// whatever the number of threads).
struct NoiseModel {
  bool enabled = true;
  double sigma_a = 0.0012;
  double sigma_b = 0.0019;
  double sigma_z0 = 0.4;
  double baseline = 0.075;       // m
  double disparity_step = 0.125; // pixels (1/8 sub-pixel disparity); 0 turns quantisation off
  double max_incidence = 78.0 * 3.14159265358979323846 / 180.0;
  double edge_jump = 0.02;       // m
  double edge_drop_prob = 0.8;
  double min_depth = 0.4;        // m, nearer is not measured
  double max_depth = 4.0;        // m, farther is not measured
  std::uint64_t seed = 0;
};
void validate(const NoiseModel& noise);

/// Bounding-volume hierarchy over the triangles of several meshes (median split), with
/// closest-hit ray queries. Built once per scene; queries are thread-safe.
class RayCaster {
 public:
  explicit RayCaster(const std::vector<TriMesh>& meshes);
  ~RayCaster();
  RayCaster(RayCaster&&) noexcept;
  RayCaster& operator=(RayCaster&&) noexcept;

  struct Hit {
    double t = std::numeric_limits<double>::infinity();  // ray parameter (o + t d)
    Vec3 normal = Vec3::Zero();                          // unit geometric normal of the face
    int mesh = -1;                                       // index of the mesh hit, -1 for none
    int face = -1;
  };
  /// Closest hit with t in (tmin, tmax]; `d` need not be unit length.
  bool intersect(const Vec3& o, const Vec3& d, Hit& hit, double tmin = 1e-9,
                 double tmax = std::numeric_limits<double>::infinity()) const;
  std::size_t num_triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What render() returns: depth (H x W, NaN where nothing is measured) and, per pixel, the index
/// of the mesh seen (-1 nothing, -2 the table) before noise and dropping.
struct RenderResult {
  DepthImage depth;
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> label;
};

/// Renders the meshes (world frame) and the optional table from camera pose `pose`
/// (camera -> world). Parallel over rows (OpenMP).
RenderResult render(const Intrinsics& K, const Iso3& pose, const std::vector<TriMesh>& meshes,
                    const Table& table, const NoiseModel& noise);
RenderResult render(const Intrinsics& K, const Iso3& pose, const RayCaster& caster,
                    const Table& table, const NoiseModel& noise);

/// Back-projects a depth image. Organised: H*W rows in row-major pixel order, NaN rows for
/// missing pixels; otherwise only the valid pixels. In the world frame when `world` (using
/// `pose`), else in the camera frame.
Points depth_to_points(const Intrinsics& K, const DepthImage& depth, const Iso3& pose, bool world,
                       bool organised);

}  // namespace bayesgrasp::vision
