// tests/support/limit_malloc.hpp -- counting heap allocations in a test
// executable (in the spirit of Drake's LimitMalloc).
//
// Linking the hoist_test_malloc object library into a test executable
// interposes malloc, calloc, realloc, memalign, aligned_alloc and
// posix_memalign for the whole process: the executable's definitions take
// precedence over libc's for every library (the model, Eigen, LCM, GLib), and
// operator new goes through malloc.  Only one such executable per process, and
// not under the sanitizers (they interpose malloc themselves).
//
// HOIST_ALLOC_TRACE=1 in the environment prints the call stack of each
// allocation counted on a watched thread (symbolize with addr2line -Cfe).
#pragma once

namespace hoist::test {

/// Allocation calls in this process since it started, on every thread.
long allocationCount();

/// Allocation calls made on threads while they were watched.
long watchedAllocationCount();

/// Counts the allocations of the calling thread while it lives (nesting is
/// not supported).  count() is what this thread allocated since construction.
class AllocationWatch {
 public:
  AllocationWatch();
  ~AllocationWatch();
  AllocationWatch(const AllocationWatch&) = delete;
  AllocationWatch& operator=(const AllocationWatch&) = delete;
  long count() const { return watchedAllocationCount() - start_; }

 private:
  long start_;
};

}  // namespace hoist::test
