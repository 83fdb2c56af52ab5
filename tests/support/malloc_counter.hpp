// For a test binary that checks code never touches the heap: interposes malloc (glibc) to
// count the calls made while counting is on. Include it in exactly one file of the binary (it
// defines malloc), and give that binary to nothing else.
#pragma once

#include <atomic>
#include <cstddef>

extern "C" void* __libc_malloc(std::size_t size);  // glibc's own allocator

namespace auvrl::test_support {
/// Whether malloc calls are counted now.
inline std::atomic<bool> g_counting_mallocs{false};
/// malloc calls while counting.
inline std::atomic<long> g_mallocs{0};
}  // namespace auvrl::test_support

extern "C" void* malloc(std::size_t size) {
  if (auvrl::test_support::g_counting_mallocs.load(std::memory_order_relaxed)) {
    auvrl::test_support::g_mallocs.fetch_add(1);
  }
  return __libc_malloc(size);
}

namespace auvrl::test_support {
/// The number of malloc calls f makes.
template <typename F>
long mallocs_during(F&& f) {
  g_mallocs = 0;
  g_counting_mallocs = true;
  f();
  g_counting_mallocs = false;
  return g_mallocs.load();
}
}  // namespace auvrl::test_support
