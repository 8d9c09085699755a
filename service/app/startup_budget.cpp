// The start-up budget: see startup_budget.hpp.
#include "startup_budget.hpp"

#include <cstdio>

#include "hoist/profile.hpp"
#include "hoist/service/lcm/budget.hpp"

namespace hoist::service::inline app {

StartupBudget measureStartupBudget(const DaemonOptions& opt, bool force) {
  StartupBudget r;
  std::string& budget_line = r.line;    // "measured start-up budget: ...", built up shaft by shaft
  std::string& budget_parts = r.parts;
  double use = 0.0;
  std::string too_slow;  // shafts whose slowest tick (one with the exact envelope) exceeds the period
  bool tight = false;    // ... or takes more than half of it
  for (std::size_t i = 0; i < opt.shafts.size(); ++i) {
    const TickBudget b = measureTickBudget(opt.shafts[i]);
    use += b.use;
    char line[320];
    if (b.worst_us > 0.5 * b.period_us && b.worst_us <= b.period_us) tight = true;
    if (b.worst_us > b.period_us) {
      std::snprintf(line, sizeof line, "%s%sa tick that needs the exact guide-rope envelope takes %.0f us, more than "
                    "the period of %.0f us", too_slow.empty() ? "" : "; ",
                    opt.labels[i].empty() ? "" : (opt.labels[i] + ": ").c_str(), b.worst_us, b.period_us);
      too_slow += line;
    }
    std::snprintf(line, sizeof line, "%s%s%.1f us per tick of %.0f us (%.1f %%, n = %d, %d substeps of max_step)",
                  budget_line.empty() ? "" : "; ", opt.labels[i].empty() ? "" : (opt.labels[i] + ": ").c_str(),
                  b.tick_us, b.period_us, 100.0 * b.use, opt.shafts[i].shaft.n,
                  substepCount(1.0 / opt.shafts[i].service.rate, opt.shafts[i].service.max_step));
    budget_line += line;
    budget_parts += (budget_parts.empty() ? "" : "; ") +
                    (opt.labels[i].empty() ? std::string() : opt.labels[i] + ": ") +
                    describeBudget(b, opt.shafts[i]);
  }
  char total[96];
  std::snprintf(total, sizeof total, " -> budget use %.1f %% of one core", 100.0 * use);
  budget_line = "measured start-up budget: " + budget_line + total;
  if (!too_slow.empty()) budget_line += "; " + too_slow;
  const bool over = use > 1.0 || !too_slow.empty();
  r.over = over;
  if (over && !force) return r;  // refused: main() says why
  if (over) budget_line += " -- OVER BUDGET, running because of --force";
  else if (use > 0.5 || tight)
    budget_line += use > 0.5 ? " -- more than half the period: little margin for jitter"
                             : " -- a tick that needs the exact guide-rope envelope takes more than half the period";
  if (over || use > 0.5 || tight) budget_line += " (" + budget_parts + ")";
  r.warn = over || use > 0.5 || tight;
  return r;
}

}  // namespace hoist::service::app
