// Bindings for cpp/bayesgrasp/geometry: mesh checks, mass properties and surface sampling.
#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/geometry/surface_sampling.hpp"
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

  py::class_<SurfaceSamples>(m, "SurfaceSamples", "Points and unit outward normals sampled on a surface.")
      .def_readonly("points", &SurfaceSamples::points, "points : ndarray (N, 3)\n    sample positions, m")
      .def_readonly("normals", &SurfaceSamples::normals,
                    "normals : ndarray (N, 3)\n    unit outward normal of the face each sample lies on")
      .def("__len__", [](const SurfaceSamples& s) { return s.points.rows(); });

  m.def(
      "sample_surface",
      [](const DArray& vertices, const IArray& faces, int n, std::uint64_t seed) {
        const TriMesh mesh = bind::mesh(vertices, faces);
        py::gil_scoped_release release;
        return sample_surface(mesh, n, seed);
      },
      py::arg("vertices"), py::arg("faces"), py::arg("n"), py::arg("seed") = 0,
      "n points sampled uniformly (area-weighted) on a mesh surface, with the faces' unit normals "
      "(SurfaceSamples). Seeded. ValueError for n <= 0 or a mesh without area.");

  m.def(
      "surface_area", [](const DArray& vertices, const IArray& faces) { return surface_area(bind::mesh(vertices, faces)); },
      py::arg("vertices"), py::arg("faces"), "Total area of a triangle mesh (m^2).");
}

}  // namespace bayesgrasp::bind
