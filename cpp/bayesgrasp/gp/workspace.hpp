// Reusable scratch memory for the large (M x N) matrices of the FITC objective. One buffer per
// matrix, kept between evaluations (no page faults after the first), aligned to 2 MiB and
// advised for transparent huge pages (Linux, madvise mode): the objective streams several
// megabyte-sized matrices through BLAS packing and column passes, and with 4 KiB pages their
// TLB misses are a measurable share of an evaluation.
#pragma once

#include <Eigen/Core>

#include <cstddef>

namespace bayesgrasp::gp::detail {

class Workspace {
 public:
  Workspace() = default;
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;
  ~Workspace();

  /// A (rows x cols) column-major view of the buffer, grown if needed; contents unspecified.
  Eigen::Map<Eigen::MatrixXd> matrix(Eigen::Index rows, Eigen::Index cols);

 private:
  double* data_ = nullptr;
  std::size_t capacity_ = 0;  // doubles
};

}  // namespace bayesgrasp::gp::detail
