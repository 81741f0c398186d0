#include "bayesgrasp/gp/workspace.hpp"

#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace bayesgrasp::gp::detail {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}

Workspace::~Workspace() { std::free(data_); }

Eigen::Map<Eigen::MatrixXd> Workspace::matrix(Eigen::Index rows, Eigen::Index cols) {
  const std::size_t n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
  if (n > capacity_) {
    std::free(data_);
    data_ = nullptr;
    capacity_ = 0;
    const std::size_t bytes = (n * sizeof(double) + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, bytes);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // advice only: ignored where THP is off
#endif
    data_ = static_cast<double*>(p);
    capacity_ = bytes / sizeof(double);
  }
  return Eigen::Map<Eigen::MatrixXd>(data_, rows, cols);
}

}  // namespace bayesgrasp::gp::detail
