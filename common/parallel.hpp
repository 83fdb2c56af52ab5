// Independent pieces of work shared among a few threads, each piece's result in its own slot, so
// that what is computed does not depend on the number of threads or on their timing.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace auvrl {

/// Calls work(worker, index) once for every index in [0, count), on `threads` threads (this one
/// among them; at most one per index): worker is in [0, threads), and each thread takes the next
/// index not yet taken, so that pieces of unequal length keep every thread busy. work must write
/// only what belongs to its index (or to its worker). The first exception a piece throws is
/// rethrown here once every thread has stopped; the indices not yet taken are then skipped.
template <typename Work>
void for_each_index(int threads, std::size_t count, Work&& work) {
  if (count == 0) return;
  const int used = static_cast<int>(
      std::min<std::size_t>(static_cast<std::size_t>(std::max(1, threads)), count));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto run = [&](int worker) {
    for (std::size_t i = next++; i < count && !failed; i = next++) {
      try {
        work(worker, i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(used - 1));
  for (int w = 1; w < used; ++w) pool.emplace_back(run, w);
  run(0);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace auvrl
