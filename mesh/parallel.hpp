#pragma once
/// \file
/// Splitting a loop over [0, count) across threads so that the result never depends on the
/// thread count: work is cut into chunks whose bounds depend on `count` and the chunk size only,
/// and anything a chunk reduces is stored per chunk and combined by the caller in chunk order.
/// (Floating-point sums combined in another order would differ in the last bits.)

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

namespace hexrefine {

/// Number of chunks of at most `chunk_size` (>= 1) items covering [0, count).
inline int64_t parallel_chunk_count(int64_t count, int64_t chunk_size) {
  return count <= 0 ? 0 : (count + chunk_size - 1) / chunk_size;
}

/// Calls body(chunk, begin, end) for every chunk [chunk * chunk_size, min(count, ...)) on up to
/// `threads` threads (the caller's thread is one of them; threads <= 1 runs inline, in chunk
/// order). Chunks are handed out one by one, so uneven chunks balance. Bodies must only write
/// state owned by their chunk. An exception thrown by a body is rethrown after every thread has
/// joined (the first one by chunk order).
template <class Body>
void parallel_chunks(int threads, int64_t count, int64_t chunk_size, Body body) {
  const int64_t chunks = parallel_chunk_count(count, chunk_size);
  auto bounds = [&](int64_t c) {
    return std::pair<int64_t, int64_t>{c * chunk_size, std::min(count, (c + 1) * chunk_size)};
  };
  const int64_t workers = std::min<int64_t>(std::max(threads, 1), chunks);
  if (workers <= 1) {
    for (int64_t c = 0; c < chunks; ++c) {
      const auto [begin, end] = bounds(c);
      body(c, begin, end);
    }
    return;
  }
  std::atomic<int64_t> next{0};
  std::vector<std::exception_ptr> failure(static_cast<size_t>(chunks));
  auto work = [&] {
    for (int64_t c = next++; c < chunks; c = next++) {
      try {
        const auto [begin, end] = bounds(c);
        body(c, begin, end);
      } catch (...) {
        failure[static_cast<size_t>(c)] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int64_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : failure)
    if (e) std::rethrow_exception(e);
}

}  // namespace hexrefine
