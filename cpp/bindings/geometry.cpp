// Bindings for cpp/bayesgrasp/geometry: mesh checks, mass properties and surface sampling.
#include "bayesgrasp/geometry/mesh.hpp"
#include "bayesgrasp/geometry/surface_sampling.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

void bind_geometry(py::module_& m) {
  py::class_<MassProperties> mp(m, "MassProperties", "Mass properties of a solid of uniform density (mesh frame).");
  mp.def(py::init([](double volume, double mass, const DArray& com, const DArray& inertia) {
           MassProperties p;
           p.volume = positive(volume, "volume");
           p.mass = positive(mass, "mass");
           p.com = vec3(com, "com");
           const RowMatrixXd I = matrix(inertia, "inertia", 3);
           if (I.rows() != 3) throw py::value_error("inertia: expected shape (3, 3), got " + shape_str(inertia));
           p.inertia = I;
           return p;
         }),
         py::arg("volume"), py::arg("mass"), py::arg("com"), py::arg("inertia"),
         "Given mass properties: volume (m^3) and mass (kg) > 0, com (3,) m, inertia (3, 3) kg m^2 about com.");
  readonly(mp, "volume", &MassProperties::volume, "float", "m^3 (negative if the faces are wound inwards)");
  readonly(mp, "mass", &MassProperties::mass, "float", "kg");
  readonly(mp, "com", &MassProperties::com, "ndarray (3,)", "centre of mass, m");
  readonly(mp, "inertia", &MassProperties::inertia, "ndarray (3, 3)", "inertia tensor about the centre of mass, kg m^2");
  mp.def(
        "to_dict",
        [](const MassProperties& p) {
          py::dict d;
          d["volume"] = p.volume;
          d["mass"] = p.mass;
          d["com"] = Eigen::Vector3d(p.com);
          d["inertia"] = Eigen::Matrix3d(p.inertia);
          return d;
        },
        "{'volume', 'mass', 'com', 'inertia'} (new arrays).")
      .def(py::pickle(
          [](const MassProperties& p) {
            return py::make_tuple(p.volume, p.mass, Eigen::Vector3d(p.com), Eigen::Matrix3d(p.inertia));
          },
          [](const py::tuple& t) {
            MassProperties p;
            p.volume = t[0].cast<double>();
            p.mass = t[1].cast<double>();
            p.com = t[2].cast<Eigen::Vector3d>();
            p.inertia = t[3].cast<Eigen::Matrix3d>();
            return p;
          }))
      .def("__repr__", [](const MassProperties& p) {
        return "MassProperties(volume=" + std::to_string(p.volume) + ", mass=" + std::to_string(p.mass) + ")";
      });

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
        return mp;
      },
      py::arg("vertices"), py::arg("faces"), py::arg("density"),
      R"doc(Mass properties of a closed triangle mesh of uniform density.

Args:
    vertices: (N, 3) float array, metres.
    faces: (M, 3) int array of vertex indices, counter-clockwise seen from outside.
    density: kg/m^3, > 0.

Returns:
    MassProperties (volume, mass, com, inertia; ``to_dict()``), in the mesh frame.)doc");

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
