// Uniform point samples on a triangle-mesh surface, with the faces' outward normals.
#pragma once

#include <cstdint>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp {

/// N x 3 points (or vectors), one per row.
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Points and unit outward normals sampled on a surface (row i of `normals` belongs to row i of
/// `points`).
struct SurfaceSamples {
  Points points;
  Points normals;
};

/// Total surface area of a mesh (m^2).
double surface_area(const TriMesh& mesh);

/// n points sampled uniformly on the surface (area-weighted triangle choice, uniform barycentric
/// coordinates), with the faces' unit normals. Seeded: the same seed gives the same samples.
/// Throws std::invalid_argument for an invalid mesh, n <= 0 or a mesh without area.
SurfaceSamples sample_surface(const TriMesh& mesh, int n, std::uint64_t seed);

}  // namespace bayesgrasp
