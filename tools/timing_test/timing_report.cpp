// hoist-replay --timing-test: the verdict and the Markdown report (pure; see
// timing_test.hpp).
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <sstream>

#include "timing_test.hpp"

namespace hoist::replay {

namespace {

std::string strf(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string strf(const char* f, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

/// Microseconds for the tables: 1 decimal below 1000 us, else whole numbers.
std::string us(double x) { return x < 1000.0 ? strf("%.1f", x) : strf("%.0f", x); }

std::string quoted(const std::string& prefix) { return "\"" + prefix + "\""; }

std::string periodUs(double rate) { return us(1e6 / rate); }

}  // namespace

const char* toString(Verdict v) {
  switch (v) {
    case Verdict::Pass: return "PASS";
    case Verdict::Fail: return "FAIL";
    case Verdict::Inconclusive: return "INCONCLUSIVE";
  }
  return "?";
}

Evaluation evaluate(const TimingResult& r, const TimingTestOptions& o) {
  Evaluation e;
  const Budgets& b = o.budgets;
  e.have_windows = !r.shafts.empty();
  for (const auto& s : r.shafts) {
    e.misses += s.misses;
    e.rejected += s.rejected;
    e.sent += s.sent;
    e.accepted += s.accepted;
    e.seq_gaps += s.seq_gaps;
    e.model_faults += s.model_faults;
    e.model_resets += s.model_resets;
    e.publish_failures += s.publish_failures;
    e.degraded_cage += s.degraded_cage;
    e.degraded_health += s.degraded_health;
    e.cage_msgs += s.cage_msgs;
    e.e2e_unmatched += s.e2e_unmatched;
    e.late_p99 = std::max(e.late_p99, s.late_p99_worst);
    e.late_max = std::max(e.late_max, s.late_max);
    e.step_p99 = std::max(e.step_p99, s.step_p99_worst);
    e.step_max = std::max(e.step_max, s.step_max);
    e.e2e.merge(s.e2e);
    if (s.windows == 0) e.have_windows = false;
  }
  const double period_us = 1e6 / o.rate;

  if (r.no_health) {
    for (const auto& s : r.shafts)
      if (!s.heard)
        e.violations.push_back(strf("no HOIST_HEALTH on %sHOIST_HEALTH within %g s: is hoist-twind running "
                                    "with the same --lcm-url and channel prefix?",
                                    s.prefix.c_str(), o.health_timeout));
    e.verdict = Verdict::Fail;
    return e;
  }

  // Budgets.
  const char* no_windows = "not measured: no HOIST_HEALTH report covered the test";
  if (e.misses > b.max_misses)
    e.violations.push_back(strf("deadline misses (--max-misses): measured %lld > allowed %lld",
                                static_cast<long long>(e.misses), static_cast<long long>(b.max_misses)));
  // Violations a late feeder cannot explain (the daemon's own: its model
  // step time, a restart, a stall) make the verdict FAIL even when the
  // feeder was late; the others (lateness, misses, end-to-end, rejections)
  // then leave it INCONCLUSIVE.
  bool own_violation = false;
  auto checkUs = [&](const std::optional<double>& budget, double measured, bool have, const char* what,
                     const char* opt, bool own = false) {
    if (!budget) return;
    if (!have) {
      e.violations.push_back(strf("%s (%s): %s", what, opt, no_windows));
    } else if (measured > *budget) {
      e.violations.push_back(strf("%s (%s): measured %s us > allowed %.10g us", what, opt, us(measured).c_str(),
                                  *budget));
      own_violation = own_violation || own;
    }
  };
  checkUs(b.late_p99_us, e.late_p99, e.have_windows, "tick lateness p99, worst window", "--max-late-p99-us");
  checkUs(b.late_max_us, e.late_max, e.have_windows, "tick lateness max", "--max-late-max-us");
  checkUs(b.step_p99_us, e.step_p99, e.have_windows, "model step time p99, worst window", "--max-step-p99-us",
          true);
  if (b.e2e_p99_us) {
    if (e.e2e.count() == 0)
      e.violations.push_back("end-to-end latency p99 (--max-e2e-p99-us): not measured: no HOIST_CAGE "
                             "message answered an input of the test");
    else if (e.e2e.quantile(0.99) > *b.e2e_p99_us)
      e.violations.push_back(strf("end-to-end latency p99 (--max-e2e-p99-us): measured %s us > allowed %.10g us",
                                  us(e.e2e.quantile(0.99)).c_str(), *b.e2e_p99_us));
  }
  if (e.rejected > b.max_rejected)
    e.violations.push_back(strf("rejected inputs (--max-rejected): measured %lld > allowed %lld",
                                static_cast<long long>(e.rejected), static_cast<long long>(b.max_rejected)));
  // The daemon must keep running and reporting.
  for (const auto& s : r.shafts) {
    if (s.restarted) {
      e.violations.push_back(strf("hoist-twind on prefix %s restarted during the test (its uptime went back)",
                                  quoted(s.prefix).c_str()));
      own_violation = true;
    }
    const double stalled = std::max(3.0, 3.0 * s.health_interval_s);
    if (!s.final_report && s.health_gap_s > stalled) {
      e.violations.push_back(strf("HOIST_HEALTH on %sHOIST_HEALTH stopped %.1f s before the end of the test "
                                  "(hoist-twind stalled or died?)",
                                  s.prefix.c_str(), s.health_gap_s));
      own_violation = true;
    }
  }

  // Notes.
  const Histogram& f = r.feeder_late;
  const bool feeder_late = f.count() > 0 && f.quantile(0.99) > period_us;
  if (feeder_late && own_violation)
    e.notes.push_back(strf("The feeder itself was late (its wake-up lateness p99 %s us exceeds one period, %s us), "
                           "but a budget the feeder cannot affect was violated (the model step time, a restart "
                           "or a stall of hoist-twind): the verdict is FAIL.",
                           us(f.quantile(0.99)).c_str(), periodUs(o.rate).c_str()));
  else if (feeder_late)
    e.notes.push_back(strf("The feeder itself was late: its wake-up lateness p99 %s us exceeds one period (%s us), "
                           "so this machine could not even feed the daemon on time; the verdict is "
                           "INCONCLUSIVE. Reduce the load, or run hoist-replay with real-time priority "
                           "(e.g. chrt -f 50) or on another core (taskset).",
                           us(f.quantile(0.99)).c_str(), periodUs(o.rate).c_str()));
  else if (f.count() > 0 && f.max() > period_us)
    e.notes.push_back(strf("The feeder was late by more than one period at least once (max %s us, %lld periods "
                           "skipped); its p99 (%s us) is within a period, so the test stands.",
                           us(f.max()).c_str(), static_cast<long long>(r.feeder_skipped),
                           us(f.quantile(0.99)).c_str()));
  const std::int64_t lost = e.sent - e.accepted;
  if (lost != 0)
    e.notes.push_back(strf("%lld of %lld inputs were not accepted by the daemon (%lld rejected; %lld sequence "
                           "gaps seen by the daemon, i.e. lost on the way).",
                           static_cast<long long>(lost), static_cast<long long>(e.sent),
                           static_cast<long long>(e.rejected), static_cast<long long>(e.seq_gaps)));
  for (const auto& s : r.shafts) {
    if (s.rejected_by_reason.empty()) continue;
    std::string reasons;
    bool range = false;
    for (const auto& [k, v] : s.rejected_by_reason) {
      reasons += strf("%s%s=%lld", reasons.empty() ? "" : ", ", k.c_str(), static_cast<long long>(v));
      range = range || k == "length_range" || k == "model_domain";
    }
    e.notes.push_back(strf("Rejected on prefix %s by reason: %s.%s", quoted(s.prefix).c_str(), reasons.c_str(),
                           range ? " The test trip left this shaft: give hoist-replay the daemon's --config "
                                   "so the trip fits it."
                                 : ""));
  }
  if (e.degraded_cage > 0 || e.degraded_health > 0)
    e.notes.push_back(strf("The twin flagged its outputs degraded while fed (%lld cage messages, %d health "
                           "reports): input stale (inputs late or lost) or a model re-initialization.",
                           static_cast<long long>(e.degraded_cage), e.degraded_health));
  if (e.model_faults > 0)
    e.notes.push_back(strf("The daemon reported %lld model fault(s) during the test.",
                           static_cast<long long>(e.model_faults)));
  if (e.publish_failures > 0)
    e.notes.push_back(strf("The daemon reported %lld LCM publish failure(s) during the test.",
                           static_cast<long long>(e.publish_failures)));
  std::int64_t feeder_fail = 0;
  for (const auto& s : r.shafts) feeder_fail += s.publish_failed;
  if (feeder_fail > 0)
    e.notes.push_back(strf("%lld HOIST_WINDER publish(es) failed in the feeder.", static_cast<long long>(feeder_fail)));
  for (const auto& s : r.shafts)
    if (!s.final_report && s.heard && !(s.health_gap_s > std::max(3.0, 3.0 * s.health_interval_s)))
      e.notes.push_back(strf("No HOIST_HEALTH on prefix %s after the end of feeding: the last %.1f s of the "
                             "test are not covered by the daemon's figures.",
                             quoted(s.prefix).c_str(), s.health_gap_s));
  {
    // The tick-wait part of the end-to-end latency.
    double rate = 0.0;
    bool wall = false;
    for (const auto& s : r.shafts) {
      if (s.clock == "wall") wall = true;
      if (s.daemon_rate > 0.0) rate = rate > 0.0 ? std::min(rate, s.daemon_rate) : s.daemon_rate;
    }
    std::string n = strf("End-to-end latency: receipt here of the first HOIST_CAGE carrying an input's seq "
                         "(input_seq) minus the publish time of that HOIST_WINDER, both on this host's wall "
                         "clock; %lld of %lld inputs were answered.",
                         static_cast<long long>(e.e2e.count()), static_cast<long long>(e.sent));
    if (wall && rate > 0.0)
      n += strf(" hoist-twind runs on --clock wall: this includes the wait for its next model tick, up to one "
                "tick period (%s us at %g Hz).",
                periodUs(rate).c_str(), rate);
    if (e.e2e_unmatched > 0)
      n += strf(" %lld answers came too late to be matched (their publish time had left the ring of recent inputs).",
                static_cast<long long>(e.e2e_unmatched));
    e.notes.push_back(n);
    bool input = false;
    for (const auto& s : r.shafts) input = input || s.clock == "input";
    if (input)
      e.notes.push_back("hoist-twind runs on --clock input: it steps on each input, so its tick lateness and "
                        "deadline misses concern only its housekeeping timer; the end-to-end latency is the "
                        "figure that matters.");
    if (wall && rate > 0.0 && rate < o.rate)
      e.notes.push_back(strf("hoist-twind steps at %g Hz, slower than the feed (%g Hz): it answers only the "
                             "latest input of each tick.",
                             rate, o.rate));
  }
  if (r.interrupted)
    e.notes.push_back(strf("Shortened run: stopped by signal %d after %.1f s of %g s; the figures cover only "
                           "that part.",
                           r.signal, r.elapsed, o.duration));

  if (e.sent == 0) {
    e.verdict = Verdict::Inconclusive;
    e.notes.push_back("Nothing was fed: there is nothing to judge.");
  } else if (feeder_late && !own_violation) {
    e.verdict = Verdict::Inconclusive;
  } else {
    e.verdict = e.violations.empty() ? Verdict::Pass : Verdict::Fail;
  }
  return e;
}

std::string formatReport(const TimingResult& r, const TimingTestOptions& o, const Evaluation& e) {
  std::ostringstream out;
  out << "VERDICT: " << toString(e.verdict);
  if (r.interrupted)
    out << strf(" (shortened run: stopped after %.1f of %g s)", r.elapsed, o.duration);
  out << "\n\n# hoist-twind timing test\n\n";
  out << "| | |\n|---|---|\n";
  out << "| command | `" << o.command << "` |\n";
  out << "| host | " << r.host << " |\n";
  out << "| date | " << r.date << " |\n";
  out << "| rate | " << strf("%g Hz (period %s us)", o.rate, periodUs(o.rate).c_str()) << " |\n";
  out << "| duration | " << strf("%g s (fed %.2f s)", o.duration, r.elapsed) << " |\n";
  out << "| shafts | " << r.shafts.size() << ": prefix";
  if (r.shafts.size() == 1) {
    out << " " << quoted(r.shafts[0].prefix);
  } else {
    out << "es ";
    for (std::size_t i = 0; i < r.shafts.size() && i < 5; ++i) out << (i ? ", " : "") << quoted(r.shafts[i].prefix);
    if (r.shafts.size() > 5) out << ", ...";
  }
  out << " |\n";
  out << "| LCM | " << (o.lcm_url.empty() ? std::string("LCM default") : o.lcm_url) << " |\n";
  if (!o.lcm_url_out.empty()) out << "| LCM, daemon outputs | " << o.lcm_url_out << " |\n";
  {
    std::string d;
    for (const auto& s : r.shafts)
      if (!s.clock.empty()) {
        d = strf("--clock %s, %g Hz", s.clock.c_str(), s.daemon_rate);
        break;
      }
    out << "| hoist-twind | " << (d.empty() ? std::string("not heard") : d) << " |\n";
  }
  out << "\n";

  if (!r.no_health) {
    const Budgets& b = o.budgets;
    auto status = [](bool configured, bool ok) { return configured ? (ok ? "ok" : "**FAIL**") : ""; };
    auto budgetUs = [](const std::optional<double>& x) { return x ? "<= " + strf("%.10g", *x) : std::string("-"); };
    const bool hw = e.have_windows;
    const double e2e99 = e.e2e.quantile(0.99);
    const double fp99 = r.feeder_late.quantile(0.99), period = 1e6 / o.rate;
    out << "## Measured\n\n";
    out << "| figure | measured | budget | |\n|---|---:|---:|:-:|\n";
    out << strf("| deadline misses | %lld | <= %lld | %s |\n", static_cast<long long>(e.misses),
                static_cast<long long>(b.max_misses), status(true, e.misses <= b.max_misses));
    auto rowUs = [&](const char* what, double v, const std::optional<double>& bud, bool have) {
      out << "| " << what << " | " << (have ? us(v) : std::string("n/a")) << " | " << budgetUs(bud) << " | "
          << status(bud.has_value(), have && (!bud || v <= *bud)) << " |\n";
    };
    rowUs("tick lateness p99, worst window [us]", e.late_p99, b.late_p99_us, hw);
    rowUs("tick lateness max [us]", e.late_max, b.late_max_us, hw);
    rowUs("model step time p99, worst window [us]", e.step_p99, b.step_p99_us, hw);
    rowUs("model step time max [us]", e.step_max, std::nullopt, hw);
    const bool he = e.e2e.count() > 0;
    rowUs("end-to-end latency p50 [us]", e.e2e.quantile(0.5), std::nullopt, he);
    rowUs("end-to-end latency p99 [us]", e2e99, b.e2e_p99_us, he);
    rowUs("end-to-end latency p99.9 [us]", e.e2e.quantile(0.999), std::nullopt, he);
    rowUs("end-to-end latency max [us]", e.e2e.max(), std::nullopt, he);
    out << strf("| rejected inputs | %lld | <= %lld | %s |\n", static_cast<long long>(e.rejected),
                static_cast<long long>(b.max_rejected), status(true, e.rejected <= b.max_rejected));
    out << strf("| inputs sent / accepted / lost | %lld / %lld / %lld | - | |\n", static_cast<long long>(e.sent),
                static_cast<long long>(e.accepted), static_cast<long long>(e.sent - e.accepted));
    out << strf("| sequence gaps seen by the daemon | %lld | - | |\n", static_cast<long long>(e.seq_gaps));
    out << strf("| model faults / re-initializations | %lld / %lld | - | |\n",
                static_cast<long long>(e.model_faults), static_cast<long long>(e.model_resets));
    out << strf("| daemon publish failures | %lld | - | |\n", static_cast<long long>(e.publish_failures));
    out << strf("| degraded outputs seen | %s | - | |\n",
                e.degraded_cage || e.degraded_health
                    ? strf("yes (%lld cage, %d health)", static_cast<long long>(e.degraded_cage), e.degraded_health)
                          .c_str()
                    : "no");
    out << strf("| feeder lateness p50 / p99 / max [us] | %s / %s / %s | p99 <= %s (one period) | %s |\n",
                us(r.feeder_late.quantile(0.5)).c_str(), us(fp99).c_str(), us(r.feeder_late.max()).c_str(),
                us(period).c_str(), r.feeder_late.count() == 0 ? "" : (fp99 <= period ? "ok" : "**LATE**"));
    out << strf("| feeder periods skipped | %lld | - | |\n", static_cast<long long>(r.feeder_skipped));
    int windows = 0;
    for (const auto& s : r.shafts) windows += s.windows;
    out << strf("| HOIST_HEALTH reports in the test | %d | - | |\n", windows);
    out << "\n";
  }

  out << "## Violated budgets\n\n";
  if (e.violations.empty()) out << "none\n";
  for (const auto& v : e.violations) out << "- " << v << "\n";
  out << "\n";

  if (r.shafts.size() > 1 && !r.no_health) {
    std::vector<const ShaftResult*> list;
    for (const auto& s : r.shafts) list.push_back(&s);
    if (list.size() > 20) {
      std::stable_sort(list.begin(), list.end(), [](const ShaftResult* a, const ShaftResult* b) {
        if (a->misses != b->misses) return a->misses > b->misses;
        if (a->late_p99_worst != b->late_p99_worst) return a->late_p99_worst > b->late_p99_worst;
        return a->e2e.quantile(0.99) > b->e2e.quantile(0.99);
      });
      list.resize(10);
      out << "## The 10 worst of " << r.shafts.size()
          << " shafts (by deadline misses, then tick lateness p99)\n\n";
    } else {
      out << "## Per shaft\n\n";
    }
    out << "| prefix | sent | accepted | lost | rejected | misses | late p99 [us] | late max [us] | step p99 [us] "
           "| e2e p99 [us] | degraded | health reports |\n";
    out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|---:|\n";
    for (const ShaftResult* s : list)
      out << strf("| %s | %lld | %lld | %lld | %lld | %lld | %s | %s | %s | %s | %s | %d |\n",
                  quoted(s->prefix).c_str(), static_cast<long long>(s->sent), static_cast<long long>(s->accepted),
                  static_cast<long long>(s->lost()), static_cast<long long>(s->rejected),
                  static_cast<long long>(s->misses), us(s->late_p99_worst).c_str(), us(s->late_max).c_str(),
                  us(s->step_p99_worst).c_str(), s->e2e.count() ? us(s->e2e.quantile(0.99)).c_str() : "n/a",
                  s->degraded_cage || s->degraded_health ? "yes" : "no", s->windows);
    out << "\n";
  }

  if (!e.notes.empty()) {
    out << "## Notes\n\n";
    for (const auto& n : e.notes) out << "- " << n << "\n";
    out << "\n";
  }
  if (r.no_health) {
    out << "Nothing was fed or measured.\n";
    return out.str();
  }
  out << "Figures from HOIST_HEALTH are deltas between the last report before feeding started and the first "
         "after it ended (windows in between for the percentiles, each window's p99 as the daemon computed "
         "it); aggregated over shafts: misses and counts summed, latencies worst case.\n";
  return out.str();
}

}  // namespace hoist::replay
