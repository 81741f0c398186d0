// Bindings for cpp/bayesgrasp/geometry: mesh checks and mass properties.
#include "bayesgrasp/geometry/mesh.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

void bind_geometry(py::module_& m) {
  m.def(
      "mass_properties",
      [](const DArray& vertices, const IArray& faces, double density) {
        const TriMesh mesh = bind::mesh(vertices, faces);
        positive(density, "density");
        MassProperties mp;
        try {
          mp = mass_properties(mesh, density);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("mesh: ") + e.what());
        }
        py::dict d;
        d["volume"] = mp.volume;
        d["mass"] = mp.mass;
        d["com"] = Eigen::Vector3d(mp.com);
        d["inertia"] = Eigen::Matrix3d(mp.inertia);
        return d;
      },
      py::arg("vertices"), py::arg("faces"), py::arg("density"),
      R"doc(Mass properties of a closed triangle mesh of uniform density.

Args:
    vertices: (N, 3) float array, metres.
    faces: (M, 3) int array of vertex indices, counter-clockwise seen from outside.
    density: kg/m^3, > 0.

Returns:
    dict with ``volume`` (m^3, negative if faces are wound inwards), ``mass`` (kg),
    ``com`` (3,) centre of mass and ``inertia`` (3, 3) inertia tensor about the centre
    of mass (kg m^2), in the mesh frame.)doc");
}

}  // namespace bayesgrasp::bind
