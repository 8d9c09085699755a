// Optional real-time settings for the calling (io_context) thread, each
// applied only when asked for and reported, never fatal:
//   * mlockall(MCL_CURRENT | MCL_FUTURE): no page faults on the tick path
//     (needs CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK);
//   * SCHED_FIFO at a priority in [1, 99] (needs CAP_SYS_NICE or
//     RLIMIT_RTPRIO; inside containers often refused);
//   * CPU affinity to a list of CPUs (pthread_setaffinity_np).
// Other threads (LCM's receive thread, the log writer) keep their settings;
// threads created by this one afterwards inherit them, so a helper that
// computes (a forecast worker) calls yieldToRealtimeLoop() first.
#pragma once

#include <string>
#include <vector>

namespace hoist::rt {

struct RealtimeRequest {
  bool mlockall = false;
  int fifo_priority = 0;   ///< 0 = do not change the scheduling policy
  std::vector<int> cpus;   ///< empty = do not change the affinity
};

struct RealtimeOutcome {
  std::string mlockall;    ///< "not requested", "on", "FAILED (...)"
  std::string scheduling;  ///< "SCHED_OTHER (not requested)", "SCHED_FIFO 80", "FAILED (...)"
  std::string affinity;    ///< "not set (CPUs 0-1)", "CPU 1", "FAILED (...)"
  bool all_granted = true; ///< every requested setting was applied
  /// One line for the start-up log.
  std::string summary() const;
};

/// "1", "0,2", "2-3" -> CPU numbers; throws std::invalid_argument naming `what`.
std::vector<int> parseCpuList(const std::string& text, const std::string& what);

/// Apply `req` to the calling thread (and, for mlockall, the process).
RealtimeOutcome applyRealtime(const RealtimeRequest& req);

/// Helper-thread side: the CALLING thread gives way to the real-time loop.
/// A thread created by the loop thread after applyRealtime() inherits its
/// SCHED_FIFO priority, and two SCHED_FIFO threads of one priority on one
/// CPU do not preempt each other: a helper computing for milliseconds (a
/// forecast worker) would hold the loop off its deadline.  This sets
/// SCHED_OTHER and then nice `nice` ([0, 19]; a larger value is always
/// allowed, so this needs no privilege), so that the loop preempts the
/// helper at once with SCHED_FIFO and outweighs it without.  Returns false,
/// with the reason in *why (if given), when either call failed.
bool yieldToRealtimeLoop(int nice, std::string* why = nullptr);

}  // namespace hoist::rt
