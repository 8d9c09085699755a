// The daemon's run report (--report PATH): the whole run's figures as JSON,
// written at stop through a temporary file and a rename.  The Daemon
// gathers the facts; this file only formats and writes them.
#pragma once

#include <cstdint>
#include <spdlog/spdlog.h>
#include <string>
#include <vector>

#include "hoist/rt/realtime.hpp"
#include "shaft_twin.hpp"

namespace hoist::service::inline app {

/// What the report says about one run.
struct RunFacts {
  std::string command_line;               ///< the daemon's command line
  double duration_s = 0.0;                ///< from the loop's start to the stop [s]
  const char* stop_reason = "";           ///< "SIGTERM", "--duration elapsed", ...
  rt::RealtimeOutcome realtime;           ///< the real-time settings granted
  std::int64_t log_lines_dropped = 0;     ///< RtLog lines lost (ring full)
  UdpmReceiver* receiver = nullptr;       ///< the own input socket (nullptr: LCM's)
  const UdpmSender* sender = nullptr;     ///< the own output socket (nullptr: LCM's)
  std::int64_t ns_ticks = 0;              ///< steady-clock ns in the ticks, without the drains and flushes in them
  std::int64_t ns_receive = 0;            ///< steady-clock ns draining the input socket
  std::int64_t ns_flush = 0;              ///< steady-clock ns in the sender's flushes
  std::int64_t cpu_ns = 0;                ///< process CPU time since the loop started [ns]
  std::vector<const ShaftTwin*> shafts;   ///< the hosted shafts
  const MissLog* misses = nullptr;        ///< the miss record (nullptr: none)
};

/// Writes the report to `path` (PATH.tmp, then renamed); errors go to
/// `log`.  False if it could not be written.
bool writeRunReport(const std::string& path, const RunFacts& f, spdlog::logger& log);

}  // namespace hoist::service::app
