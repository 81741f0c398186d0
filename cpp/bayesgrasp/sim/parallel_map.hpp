// out[i] = fn(i) for i in [0, n), in OpenMP threads (thread_count: 0 = all cores), results in
// input order. The first exception thrown by fn is rethrown after the loop.
#pragma once

#include <exception>
#include <vector>

#include "bayesgrasp/common/parallel.hpp"

namespace bayesgrasp {

template <class R, class F>
std::vector<R> parallel_map(long n, int threads, int chunk, F&& fn) {
  const int nt = thread_count_for(threads, n);
  std::vector<R> out(static_cast<size_t>(n));
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic, chunk) num_threads(nt)
  for (long i = 0; i < n; ++i) {
    try {
      out[i] = fn(i);
    } catch (...) {
#pragma omp critical(bg_parallel_map_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  return out;
}

}  // namespace bayesgrasp
