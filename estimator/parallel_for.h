#pragma once
// A parallel loop over independent items (the segments of a fit) on a few threads, for the
// passes the estimators make outside Ceres' own parallel evaluation.

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace slideid {

/// Calls body(i) for every i in [0, n), on min(threads, n) threads, each taking the next
/// item as it finishes one (segments differ in cost: a sliding one takes more Newton
/// iterations per step than a resting one, and fixed blocks left one thread waiting);
/// threads <= 1 runs in the calling thread. body must be safe to call concurrently for
/// different i, and must not throw.
template <typename Body>
void ParallelFor(int n, int threads, const Body& body) {
  const int workers = std::min(threads, n);
  if (workers <= 1) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i = next++; i < n; i = next++) body(i);
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace slideid
