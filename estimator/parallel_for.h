#pragma once
// A parallel loop over independent items (the segments of a fit) on a few threads, for the
// passes the estimators make outside Ceres' own parallel evaluation.

#include <algorithm>
#include <thread>
#include <vector>

namespace slideid {

/// Calls body(i) for every i in [0, n), on min(threads, n) threads in contiguous blocks;
/// threads <= 1 runs in the calling thread. body must be safe to call concurrently for
/// different i, and must not throw.
template <typename Body>
void ParallelFor(int n, int threads, const Body& body) {
  const int workers = std::min(threads, n);
  if (workers <= 1) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  auto run_block = [&](int w) {
    const int begin = static_cast<int>(static_cast<long long>(n) * w / workers);
    const int end = static_cast<int>(static_cast<long long>(n) * (w + 1) / workers);
    for (int i = begin; i < end; ++i) body(i);
  };
  for (int w = 1; w < workers; ++w) pool.emplace_back(run_block, w);
  run_block(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace slideid
