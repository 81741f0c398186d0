// Triangle meshes, rigid poses and mass properties: the types every other concept shares.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace bayesgrasp {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Iso3 = Eigen::Isometry3d;
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// A triangle mesh in metres. Faces index rows of V, counter-clockwise seen from outside.
struct TriMesh {
  Vertices V;
  Faces F;
};

/// Throws std::invalid_argument naming the problem: no vertices/faces, non-finite
/// vertices, or face indices out of range.
void validate_mesh(const TriMesh& mesh);

/// Mass properties of a closed mesh of uniform density (kg/m^3), by the divergence
/// theorem over signed tetrahedra. `inertia` is about the centre of mass, in the mesh frame.
struct MassProperties {
  double volume = 0.0;  // m^3 (signed: negative if the faces are wound inwards)
  double mass = 0.0;    // kg
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();  // kg m^2
};
MassProperties mass_properties(const TriMesh& mesh, double density);

/// Largest distance from `point` to the mesh's vertices (the torque scale of the GWS).
double max_vertex_distance(const TriMesh& mesh, const Vec3& point);

/// Axis-aligned bounds of the vertices.
Eigen::AlignedBox3d bounds(const TriMesh& mesh);

/// The mesh with every vertex transformed.
TriMesh transformed(const TriMesh& mesh, const Iso3& T);

/// A pose on the table: translation (x, y, z) and rotation yaw about +z.
Iso3 planar_pose(double x, double y, double yaw, double z = 0.0);

/// Pose from a 4x4 homogeneous matrix (row-major array of 16); throws if the rotation
/// block is not orthonormal within 1e-6 or entries are not finite.
Iso3 pose_from_matrix(const Eigen::Matrix4d& M);

}  // namespace bayesgrasp
