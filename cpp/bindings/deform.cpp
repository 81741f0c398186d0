// Thin binding of the non-rigid registration (Coherent Point Drift, deform/cpd.hpp): options,
// the field and the result; point arrays checked here, the options in the core; GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bayesgrasp/deform/cpd.hpp"
#include "options.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

namespace {

deform::Points cloud(const DArray& a, const char* name) { return deform::Points(matrix(a, name, 3)); }

py::array_t<double> out(const deform::Points& P) { return to_numpy(RowMatrixXd(P)); }

}  // namespace

void bind_deform(py::module_& m) {
  using deform::CpdOptions;
  using deform::CpdResult;
  using deform::DisplacementField;
  OptionClass<CpdOptions>(m, "CpdOptions", "Coherent Point Drift (non-rigid) settings.")
      .field("beta", &CpdOptions::beta, "float", "kernel width in the model's RMS radii (larger: smoother)")
      .field("lam", &CpdOptions::lam, "float", "lambda, the weight of the field's smoothness term (larger: less motion)")
      .field("outlier_weight", &CpdOptions::outlier_weight, "float", "w in [0, 1): the uniform outlier component's share")
      .field("max_iterations", &CpdOptions::max_iterations, "int", "EM iterations at most")
      .field("tolerance", &CpdOptions::tolerance, "float", "stop when the variance changes by less than this fraction")
      .field("rank", &CpdOptions::rank, "int", "Nystrom landmarks (0 or >= the model's points: exact)")
      .field("cutoff", &CpdOptions::cutoff, "float", "pairs farther apart than this many sigma are left out of the E-step (0: every pair)")
      .field("threads", &CpdOptions::threads, "int", "threads of the E-step (0 = all cores)")
      .validator([](const CpdOptions& o) { deform::validate(o); })
      .finish();

  py::class_<DisplacementField>(m, "DisplacementField",
                                "v(z) = sum_k G(z, l_k) a_k: the smooth displacement CPD found, defined everywhere.")
      .def_property_readonly("landmarks", [](const DisplacementField& f) { return out(f.landmarks); },
                             "(K, 3) the kernel's centres (input units)")
      .def_property_readonly("coefficients",
                             [](const DisplacementField& f) { return out(deform::Points(f.coefficients)); },
                             "(K, 3) their weights")
      .def_readonly("beta", &DisplacementField::beta, "kernel width (input units)")
      .def("warp", [](const DisplacementField& f, const DArray& points) {
             deform::Points P = cloud(points, "points");
             deform::Points W;
             {
               py::gil_scoped_release release;
               W = f.warp(P);
             }
             return out(W);
           }, py::arg("points"), "(N, 3) points moved by the field: z + v(z)");

  py::class_<CpdResult> r(m, "CpdResult", "The warp of a model onto an observed cloud.");
  r.def_property_readonly("moved", [](const CpdResult& x) { return out(x.moved); }, "(M, 3) the model's points warped");
  readonly(r, "field", &CpdResult::field, "DisplacementField", "the displacement, to warp any other point");
  readonly(r, "sigma2", &CpdResult::sigma2, "float", "final mixture variance (m^2)");
  readonly(r, "residual", &CpdResult::residual, "float", "RMS distance from each observed point to the nearest moved one (m)");
  readonly(r, "iterations", &CpdResult::iterations, "int", "EM iterations run");
  readonly(r, "converged", &CpdResult::converged, "bool", "the variance settled before max_iterations");

  m.def("coherent_point_drift",
        [](const DArray& model, const DArray& observed, const CpdOptions& options) {
          deform::Points Y = cloud(model, "model"), X = cloud(observed, "observed");
          deform::validate(options);
          py::gil_scoped_release release;
          return deform::coherent_point_drift(Y, X, options);
        },
        py::arg("model"), py::arg("observed"), py::arg("options") = CpdOptions{},
        "Warps model (M, 3) onto observed (N, 3) (one frame, after the rigid registration) by non-rigid "
        "Coherent Point Drift (Myronenko & Song 2010); returns a CpdResult.");
}

}  // namespace bayesgrasp::bind
