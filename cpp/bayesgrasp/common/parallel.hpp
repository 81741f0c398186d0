// The one rule for thread counts, used by every batched call and every binding:
// 0 = all hardware threads, a positive count is capped at the hardware threads, negative is an error;
// and the one parallel loop over independent work items (parallel_map).
#pragma once

#include <omp.h>

#include <algorithm>
#include <exception>
#include <vector>
#include <stdexcept>
#include <string>

namespace bayesgrasp {

/// Threads to use for a request: 0 -> all hardware threads; n > 0 -> min(n, hardware threads).
/// Throws std::invalid_argument naming `name` for a negative request.
inline int thread_count(long long requested, const char* name = "threads") {
  if (requested < 0)
    throw std::invalid_argument(std::string(name) + ": must be >= 0 (0 = all cores), got " +
                                std::to_string(requested));
  const int hardware = std::max(1, omp_get_num_procs());
  if (requested == 0) return hardware;
  return static_cast<int>(std::min<long long>(requested, hardware));
}

/// thread_count capped at the number of work items (at least 1).
inline int thread_count_for(long long requested, long long items, const char* name = "threads") {
  const int t = thread_count(requested, name);
  return static_cast<int>(std::max<long long>(1, std::min<long long>(t, items)));
}

/// out[i] = fn(i) for i in [0, n), in OpenMP threads (thread_count: 0 = all cores), results in
/// input order; the first exception thrown by fn is rethrown after the loop.
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
