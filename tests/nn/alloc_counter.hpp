// Counts the heap allocations of the whole process, to check that update loops allocate nothing.
#pragma once

namespace auvrl::test {

/// While an AllocationCounter lives, every malloc/calloc/realloc/aligned allocation in the
/// process (operator new included, since it calls malloc; Eigen's aligned_malloc too) is counted.
/// Works by defining the malloc family in the test executable, forwarding to glibc.
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  /// Allocations since construction.
  long count() const;
};

}  // namespace auvrl::test
