// timing_test.hpp -- hoist-replay --timing-test: a soft-real-time check of a
// running hoist-twind on a deployment machine.
//
// The feeder publishes HOIST_WINDER at `rate` Hz for `duration` s on every
// channel prefix (one message per prefix per period; a trapezoid trip down
// and up again, with the encoder length, so the cage always moves; seq
// contiguous from 0; utime = wall clock at publish).  The listener hears
// HOIST_HEALTH and HOIST_CAGE on the same prefixes.  The results are judged
// against budgets (evaluate) and written as Markdown (formatReport).
//
// evaluate() and formatReport() are pure (timing_report.cpp, unit-tested);
// runTimingTest() does the LCM work (timing_run.cpp).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "timing_stats.hpp"

namespace hoist::replay {

struct Budgets {
  std::optional<double> late_p99_us;  ///< worst window's tick lateness p99
  std::optional<double> late_max_us;  ///< largest tick lateness
  std::optional<double> step_p99_us;  ///< worst window's model step time p99
  std::optional<double> e2e_p99_us;   ///< input -> cage output latency p99
  std::int64_t max_misses = 0;        ///< deadline misses (summed over shafts)
  std::int64_t max_rejected = 0;      ///< rejected inputs (summed over shafts)
};

struct TimingTestOptions {
  double rate = 100.0;      ///< feed rate [Hz], 1..1000
  double duration = 60.0;   ///< [s]
  std::vector<std::string> prefixes{""};
  Budgets budgets;
  std::string report_path;  ///< "" = none
  std::string lcm_url;      ///< resolved ("" = LCM default)
  std::string lcm_url_out;  ///< the daemon's [service] lcm_url_out: its outputs are read there ("" = lcm_url)
  std::string command;      ///< the command line, for the report
  bool progress = false;    ///< one line per second on stderr
  bool quiet = false;
  double l0 = 50.0;         ///< trip start [m]
  double travel = 250.0;    ///< trip length [m] (> 0 down first, < 0 up first)
  double vmax = 5.0, amax = 1.0;
  double health_timeout = 5.0;  ///< first HOIST_HEALTH must come within this [s]
};

/// What was measured on one shaft (channel prefix).
struct ShaftResult {
  std::string prefix;
  bool heard = false;              ///< any HOIST_HEALTH at all
  bool final_report = false;       ///< a HOIST_HEALTH after the last input
  bool restarted = false;          ///< daemon uptime went backwards
  double health_gap_s = 0.0;       ///< feed end minus the last health's utime, if no final report [s]
  double health_interval_s = 1.0;  ///< observed interval between health reports [s]
  int windows = 0;                 ///< health reports within the test
  std::string clock;               ///< daemon's clock ("wall"/"input")
  double daemon_rate = 0.0;        ///< daemon's model step rate [Hz]
  std::int64_t sent = 0;           ///< HOIST_WINDER published
  std::int64_t publish_failed = 0; ///< feeder's own publish errors
  // Deltas last minus first health seen:
  std::int64_t misses = 0, rejected = 0, accepted = 0, seq_gaps = 0, model_faults = 0,
               model_resets = 0, publish_failures = 0, nonfinite_blocked = 0;
  std::map<std::string, std::int64_t> rejected_by_reason;  ///< non-zero deltas only
  // Over the windows within the test:
  double late_p99_worst = 0.0, late_max = 0.0, step_p99_worst = 0.0, step_max = 0.0;
  int degraded_health = 0;          ///< health reports with degraded set, while fed
  std::int64_t degraded_cage = 0;   ///< cage messages with degraded set, while fed
  std::int64_t cage_msgs = 0;       ///< HOIST_CAGE messages answering our inputs
  Histogram e2e;                    ///< first cage output per input: latency [us]
  std::int64_t e2e_unmatched = 0;   ///< input_seq too old for the ring
  std::int64_t lost() const { return sent - accepted; }
};

struct TimingResult {
  std::vector<ShaftResult> shafts;
  Histogram feeder_late;               ///< feeder wake-up minus its deadline [us]
  std::int64_t feeder_skipped = 0;     ///< periods skipped (feeder more than a period late)
  double elapsed = 0.0;                ///< feeding time [s]
  bool interrupted = false;            ///< stopped by a signal
  int signal = 0;
  bool no_health = false;              ///< some shaft never reported
  std::string host, date;              ///< uname -n, ISO 8601 UTC
};

enum class Verdict { Pass, Fail, Inconclusive };
const char* toString(Verdict v);

struct Evaluation {
  Verdict verdict = Verdict::Pass;
  std::vector<std::string> violations;  ///< "budget: measured X > allowed Y"
  std::vector<std::string> notes;       ///< everything else worth reading
  // Aggregates over the shafts:
  std::int64_t misses = 0, rejected = 0, sent = 0, accepted = 0, seq_gaps = 0, model_faults = 0,
               model_resets = 0, publish_failures = 0, degraded_cage = 0, cage_msgs = 0, e2e_unmatched = 0;
  int degraded_health = 0;
  double late_p99 = 0.0, late_max = 0.0, step_p99 = 0.0, step_max = 0.0;
  Histogram e2e;
  bool have_windows = false;  ///< at least one health window in the test on every shaft
};

Evaluation evaluate(const TimingResult& r, const TimingTestOptions& o);

/// The Markdown report; its first line is "VERDICT: PASS|FAIL|INCONCLUSIVE"
/// (followed by " (shortened run: ...)" after Ctrl-C).
std::string formatReport(const TimingResult& r, const TimingTestOptions& o, const Evaluation& e);

/// Run the test.  Returns the exit status: 0 PASS, 1 FAIL or INCONCLUSIVE,
/// 128 + signal when stopped early by a signal (after reporting).
int runTimingTest(const TimingTestOptions& o);

}  // namespace hoist::replay
