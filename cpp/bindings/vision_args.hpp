// Argument conversions shared by the vision bindings (camera, segmentation, registration): a list
// item as a 2-tuple, and (N, 3) point arrays in and out. Errors are ValueErrors naming the argument.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <string>

#include "bayesgrasp/vision/camera.hpp"
#include "validate.hpp"

namespace bayesgrasp::bind {

// Item i of a Python list of 2-tuples, or a ValueError naming it ("name: expected a (what) tuple").
inline py::tuple pair_at(const py::list& list, std::size_t i, const std::string& name, const char* what) {
  py::tuple t;
  try {
    t = list[i].cast<py::tuple>();
  } catch (const py::cast_error&) {
    throw py::value_error(name + ": expected a (" + what + ") tuple");
  }
  if (t.size() != 2) throw py::value_error(name + ": expected a (" + what + ") tuple");
  return t;
}

// An (N, 3) cloud; NaN rows allowed if allow_nan (the core drops them), infinity never.
inline vision::Points points_arg(const DArray& a, const char* name, bool allow_nan) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shape_str(a));
  vision::Points P = Eigen::Map<const vision::Points>(a.data(), a.shape(0), 3);
  if (!allow_nan && !P.allFinite()) throw py::value_error(std::string(name) + ": contains NaN or infinity");
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    if (P.row(i).array().isInf().any()) throw py::value_error(std::string(name) + ": contains infinity");
  return P;
}

inline py::array_t<double> points_out(const vision::Points& P) {
  py::array_t<double> out({static_cast<py::ssize_t>(P.rows()), static_cast<py::ssize_t>(3)});
  std::copy(P.data(), P.data() + P.size(), out.mutable_data());
  return out;
}

}  // namespace bayesgrasp::bind
