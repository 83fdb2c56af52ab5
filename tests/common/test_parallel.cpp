// for_each_index: every index once, on the threads asked for, and a piece's exception rethrown
// once every thread has stopped.
#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <vector>

#include "common/parallel.hpp"

namespace auvrl {
namespace {

TEST(ForEachIndex, RunsEveryIndexOnceOnTheWorkersAsked) {
  for (const int threads : {1, 2, 5}) {
    std::vector<int> runs(37, 0);
    std::vector<int> worker_of(37, -1);
    for_each_index(threads, runs.size(), [&](int worker, std::size_t i) {
      ++runs[i];
      worker_of[i] = worker;
    });
    for (std::size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(runs[i], 1) << threads << " threads, index " << i;
      EXPECT_GE(worker_of[i], 0);
      EXPECT_LT(worker_of[i], threads);
    }
  }
  // No more workers than indices, and nothing to do is nothing done.
  std::set<int> workers;
  for_each_index(8, 2, [&](int worker, std::size_t) { workers.insert(worker); });
  for (const int w : workers) EXPECT_LT(w, 2);
  bool called = false;
  for_each_index(4, 0, [&](int, std::size_t) { called = true; });
  EXPECT_FALSE(called);
}

TEST(ForEachIndex, RethrowsAPiecesExceptionAfterTheThreadsStop) {
  std::atomic<int> done{0};
  EXPECT_THROW(for_each_index(2, 100,
                              [&](int, std::size_t i) {
                                if (i == 3) throw std::runtime_error("piece 3");
                                ++done;
                              }),
               std::runtime_error);
  EXPECT_LT(done.load(), 100);
}

}  // namespace
}  // namespace auvrl
