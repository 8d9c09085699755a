// Start-up budget measurement: see hoist/service/budget.hpp.
#include "hoist/service/budget.hpp"

#include <chrono>
#include <cmath>

#include "hoist/service/twin_core.hpp"

namespace hoist::svc {

TickBudget measureTickBudget(const TwinConfig& cfg, int max_ticks, double max_seconds) {
  using Clock = std::chrono::steady_clock;
  TwinConfig c = cfg;
  c.service.clock = ClockMode::Input;  // one step per fed sample = one tick's work
  TwinCore core(c, ClockMode::Input);
  TickBudget b;
  b.period_us = 1e6 / c.service.rate;
  const LengthRange r = core.validRange();
  // A constant-speed trip toward the farther end of the shaft.
  const double v = c.shaft.l0 - r.lo < r.hi - c.shaft.l0 ? 2.0 : -2.0;
  const auto dt_us = static_cast<std::int64_t>(std::llround(b.period_us));
  const auto start = Clock::now();
  double sum = 0.0;
  int counted = 0;
  for (int k = 0; k < max_ticks; ++k) {
    WinderSample s;
    s.utime = 1'000'000'000 + k * dt_us;
    s.seq = k;
    s.v = v;
    const auto t0 = Clock::now();
    core.onInput(s, static_cast<double>(k) * 1e-6 * static_cast<double>(dt_us));
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    if (k >= 2) {  // the first ones initialize and warm the caches
      sum += us;
      ++counted;
      b.max_us = std::max(b.max_us, us);
    }
    b.ticks = k + 1;
    if (counted >= 3 && std::chrono::duration<double>(Clock::now() - start).count() > max_seconds) break;
  }
  b.tick_us = counted ? sum / counted : 0.0;
  b.use = b.tick_us / b.period_us;
  return b;
}

}  // namespace hoist::svc
