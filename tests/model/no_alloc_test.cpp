// The fast path's step() allocates nothing after start-up: a counting global
// operator new and Eigen's runtime malloc guard both watch the loop.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "hoist/fast_solver.hpp"
#include "hoist/simulator.hpp"

namespace {
std::atomic<long> g_allocs{0};
}

void* operator new(std::size_t n) {
  g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace hoist;

TEST(NoAlloc, FastStepAndEnvelopeAllocateNothing) {
  for (int n : {10, 50, 200}) {
    ShaftParams p;
    p.n = n;
    p.Tb2 = 32000;  // distinct ropes: both modal bases in use
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver s(model);
    GuideRopeEnvelope env(*model, 401);
    const HoistProfile prof = HoistProfile::trapezoid();
    s.initialize(0.0, prof.at(0.0));
    s.step(0.01, prof.at(0.01));  // first step may size nothing new, but allow it
    const long before = g_allocs.load();
    Eigen::internal::set_is_malloc_allowed(false);
    double acc = 0;
    for (int k = 2; k <= 3000; ++k) {
      const double t = k * 0.01;
      s.step(t, prof.at(t));
      acc += env.evaluate(s);
    }
    Eigen::internal::set_is_malloc_allowed(true);
    EXPECT_EQ(g_allocs.load() - before, 0) << "n = " << n;
    EXPECT_TRUE(std::isfinite(acc));
  }
}

TEST(NoAlloc, CounterSeesAllocations) {
  // The guard itself works (a test that cannot fail is a defect).
  const long before = g_allocs.load();
  auto* v = new std::vector<double>(100);
  delete v;
  EXPECT_GE(g_allocs.load() - before, 2);
}
