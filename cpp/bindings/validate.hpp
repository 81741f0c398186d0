// Input checks shared by the bindings: every array a user passes is checked for shape,
// dtype (converted to float64/int32 by pybind11) and finiteness, and a ValueError names
// the offending argument. Nothing a user passes may crash the interpreter.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <string>
#include <vector>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp::bind {

namespace py = pybind11;
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using DArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IArray = py::array_t<int, py::array::c_style | py::array::forcecast>;

inline std::string shape_str(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Checks a float array is 2-D with `cols` columns (any if cols < 0) and all finite;
/// returns it as a row-major Eigen matrix (copy).
inline RowMatrixXd matrix(const DArray& a, const char* name, py::ssize_t cols = -1,
                          bool allow_empty = false) {
  if (a.ndim() != 2 || (cols >= 0 && a.shape(1) != cols))
    throw py::value_error(std::string(name) + ": expected shape (N, " +
                          (cols >= 0 ? std::to_string(cols) : std::string("D")) + "), got " + shape_str(a));
  if (!allow_empty && a.shape(0) == 0) throw py::value_error(std::string(name) + ": is empty");
  Eigen::Map<const RowMatrixXd> m(a.data(), a.shape(0), a.shape(1));
  if (!m.allFinite()) throw py::value_error(std::string(name) + ": contains NaN or infinity");
  return m;
}

/// Checks a float array is 1-D with `n` entries (any if n < 0) and all finite.
inline Eigen::VectorXd vector(const DArray& a, const char* name, py::ssize_t n = -1) {
  if (a.ndim() != 1 || (n >= 0 && a.shape(0) != n))
    throw py::value_error(std::string(name) + ": expected shape (" +
                          (n >= 0 ? std::to_string(n) : std::string("N")) + ",), got " + shape_str(a));
  Eigen::Map<const Eigen::VectorXd> v(a.data(), a.shape(0));
  if (!v.allFinite()) throw py::value_error(std::string(name) + ": contains NaN or infinity");
  return v;
}

/// A 3-vector from a (3,) float array (shape checked; the core checks the values).
inline Vec3 vec3(const DArray& a, const char* name) {
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw py::value_error(std::string(name) + ": expected shape (3,), got " + shape_str(a));
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

inline double finite(double x, const char* name) {
  if (!std::isfinite(x)) throw py::value_error(std::string(name) + ": must be finite, got " + std::to_string(x));
  return x;
}

inline double positive(double x, const char* name) {
  if (!(x > 0.0) || !std::isfinite(x))
    throw py::value_error(std::string(name) + ": must be positive and finite, got " + std::to_string(x));
  return x;
}

/// A 4x4 homogeneous pose.
inline Iso3 pose(const DArray& a, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(std::string(name) + ": expected shape (4, 4), got " + shape_str(a));
  Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> m(a.data());
  try {
    return pose_from_matrix(m);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string(name) + ": " + e.what());
  }
}

/// N 4x4 homogeneous poses from an (N, 4, 4) array; errors name the argument and the row.
inline std::vector<Iso3> poses(const DArray& a, const char* name) {
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4)
    throw py::value_error(std::string(name) + ": expected shape (N, 4, 4), got " + shape_str(a));
  std::vector<Iso3> out(static_cast<size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> m(a.data() + 16 * i);
    try {
      out[static_cast<size_t>(i)] = pose_from_matrix(m);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string(name) + "[" + std::to_string(i) + "]: " + e.what());
    }
  }
  return out;
}

/// A triangle mesh from (V: (N, 3) float, F: (M, 3) int).
inline TriMesh mesh(const DArray& V, const IArray& F, const char* name = "mesh") {
  TriMesh m;
  m.V = matrix(V, (std::string(name) + " vertices").c_str(), 3);
  if (F.ndim() != 2 || F.shape(1) != 3)
    throw py::value_error(std::string(name) + " faces: expected shape (M, 3), got " + shape_str(F));
  m.F = Eigen::Map<const Faces>(F.data(), F.shape(0), 3);
  try {
    validate_mesh(m);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string(name) + ": " + e.what());
  }
  return m;
}

inline py::array_t<double> to_numpy(const RowMatrixXd& m) {
  py::array_t<double> out({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), out.mutable_data());
  return out;
}

/// A pose as a (4, 4) float array (copy).
inline py::array_t<double> to_numpy(const Iso3& T) {
  py::array_t<double> out({4, 4});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o(r, c) = T.matrix()(r, c);
  return out;
}

/// Poses as an (N, 4, 4) float array (copy).
inline py::array_t<double> to_numpy(const std::vector<Iso3>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto o = out.mutable_unchecked<3>();
  for (size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(static_cast<py::ssize_t>(i), r, c) = poses[i].matrix()(r, c);
  return out;
}

/// Read-only numpy view of memory owned by the Python object `owner` (which the array keeps
/// alive): `shape` items of dtype `dt` at `data`, `strides` in bytes. Results bound as classes
/// expose their C++ arrays this way, without copies. Flags of 0/1 bytes may be viewed as bool.
inline py::array readonly_view(const py::dtype& dt, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
                               const void* data, py::handle owner) {
  py::ssize_t n = 1;
  for (py::ssize_t d : shape) n *= d;
  py::array out = n == 0 ? py::array(dt, shape, strides) : py::array(dt, shape, strides, data, owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// Read-only (n,) view of one scalar member of n consecutive structs (an empty array if n = 0).
template <class T, class F>
py::array field_view(const T* first, size_t n, F T::*member, py::handle owner) {
  return readonly_view(py::dtype::of<F>(), {static_cast<py::ssize_t>(n)}, {static_cast<py::ssize_t>(sizeof(T))},
                       n ? &(first->*member) : nullptr, owner);
}

/// Read-only (n, 3) view of one Vec3 member of n consecutive structs.
template <class T>
py::array vec3_field_view(const T* first, size_t n, Vec3 T::*member, py::handle owner) {
  const auto d = static_cast<py::ssize_t>(sizeof(double));
  return readonly_view(py::dtype::of<double>(), {static_cast<py::ssize_t>(n), 3}, {static_cast<py::ssize_t>(sizeof(T)), d},
                       n ? (first->*member).data() : nullptr, owner);
}

/// Read-only (N, 4, 4) view of N poses (Iso3 stores its 4x4 matrix column-major).
inline py::array poses_view(const Iso3* poses, size_t n, py::handle owner) {
  const auto item = static_cast<py::ssize_t>(sizeof(Iso3)), d = static_cast<py::ssize_t>(sizeof(double));
  return readonly_view(py::dtype::of<double>(), {static_cast<py::ssize_t>(n), 4, 4}, {item, d, 4 * d},
                       n ? poses[0].matrix().data() : nullptr, owner);
}

/// Read-only (4, 4) view of one pose.
inline py::array pose_view(const Iso3& pose, py::handle owner) {
  const auto d = static_cast<py::ssize_t>(sizeof(double));
  return readonly_view(py::dtype::of<double>(), {4, 4}, {d, 4 * d}, pose.matrix().data(), owner);
}

}  // namespace bayesgrasp::bind
