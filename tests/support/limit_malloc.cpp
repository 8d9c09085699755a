// The malloc interposer of tests/support/limit_malloc.hpp.
#include "limit_malloc.hpp"

#include <execinfo.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {
thread_local bool t_watch = false;  // initial-exec TLS in the executable: no allocation
std::atomic<long> g_allocs{0};
std::atomic<long> g_watched{0};
const bool g_trace = std::getenv("HOIST_ALLOC_TRACE") != nullptr;

inline void count() {
  g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (!t_watch) return;
  g_watched.fetch_add(1, std::memory_order_relaxed);
  if (g_trace) {
    t_watch = false;
    void* frames[24];
    const int n = backtrace(frames, 24);
    (void)!write(2, "---- allocation\n", 16);
    backtrace_symbols_fd(frames, n, 2);
    t_watch = true;
  }
}
}  // namespace

extern "C" {
void* malloc(size_t n) {
  count();
  return __libc_malloc(n);
}
void* calloc(size_t a, size_t b) {
  count();
  return __libc_calloc(a, b);
}
void* realloc(void* p, size_t n) {
  count();
  return __libc_realloc(p, n);
}
void* memalign(size_t al, size_t n) {
  count();
  return __libc_memalign(al, n);
}
void* aligned_alloc(size_t al, size_t n) {
  count();
  return __libc_memalign(al, n);
}
int posix_memalign(void** out, size_t al, size_t n) {
  count();
  void* p = __libc_memalign(al, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) { __libc_free(p); }
}

namespace hoist::test {

long allocationCount() { return g_allocs.load(); }
long watchedAllocationCount() { return g_watched.load(); }

AllocationWatch::AllocationWatch() : start_(g_watched.load()) { t_watch = true; }
AllocationWatch::~AllocationWatch() { t_watch = false; }

}  // namespace hoist::test
