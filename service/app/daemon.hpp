// hoist-twind's event loop: one Boost.Asio io_context that owns
//   * the LCM socket (lcm::LCM::getFileno() watched by a stream_descriptor,
//     drained with handleTimeout(0): no polling, no extra thread of ours);
//   * a steady_timer on an absolute schedule, deadline_k = start + k * period
//     (k counts periods; a tick that starts more than one period late is a
//     deadline miss, and the schedule skips the missed periods);
//   * a signal_set for SIGINT/SIGTERM (clean stop, final health report).
// All math is in TwinCore (hoist_twin); this file only moves bytes.
//
// Real time: every outgoing message object and its encode buffer are
// allocated at start-up; the tick path encodes into them and publishes the
// raw bytes (lcm::LCM::publish(channel, data, len)).  Logging goes through an
// asynchronous spdlog logger (non-blocking, overrun-oldest) and only for rare
// events (alarms, rejected inputs, rate-limited per reason).
#pragma once

#include <utility>  // before Asio: Boost 1.74 awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <spdlog/spdlog.h>
#include <string>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/service/config.hpp"
#include "hoist/service/health.hpp"
#include "hoist/service/twin_core.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::svc {

struct DaemonOptions {
  TwinConfig cfg;          ///< effective configuration (command line applied)
  std::string lcm_url;     ///< resolved URL ("" = LCM default)
  double duration = 0.0;   ///< stop after this many seconds (0 = run until signalled)
  // Test-only fault injection (hidden options, tests/hardening):
  double inject_fault_at = -1.0;  ///< wall time [s] at which the model state is treated as non-finite once
  int fail_publish_every = 0;     ///< every N-th LCM publish is treated as failed (0 = never)
};

class Daemon {
 public:
  Daemon(DaemonOptions opt, std::shared_ptr<spdlog::logger> log);
  ~Daemon();
  /// Runs until SIGINT/SIGTERM (or --duration); returns the exit status.
  int run();

 private:
  using Clock = std::chrono::steady_clock;

  void armLcm();
  void onLcmReadable(const boost::system::error_code& ec);
  void onWinder(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void onAck(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void armTimer();
  void onTick(const boost::system::error_code& ec);
  void stop(const char* why);

  double wallNow() const;  ///< seconds since start (steady clock)
  void publishCage(std::int64_t utime);
  void publishShape(std::int64_t utime);
  void publishHealth(bool final_report = false);
  void drainAlarmEvents();
  bool publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len);
  template <class Msg>
  bool encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf);
  void logReject(RejectReason r, const char* detail);

  DaemonOptions opt_;
  std::shared_ptr<spdlog::logger> log_;
  Channels ch_;
  boost::asio::io_context io_;
  lcm::LCM lcm_;
  boost::asio::posix::stream_descriptor lcm_fd_;
  boost::asio::steady_timer timer_;
  boost::asio::signal_set signals_;
  TwinCore core_;

  // schedule
  Clock::time_point start_;
  Clock::duration period_;
  std::int64_t k_ = 0;  ///< index of the next deadline
  std::int64_t ticks_ = 0, deadline_misses_ = 0;
  int cage_div_ = 1, shape_div_ = 1, health_div_ = 1;
  double last_shape_t_ = -1e300;  ///< input clock: model time of the last shape message
  std::int64_t ticks_since_health_ = 0;
  double last_health_wall_ = 0.0;
  bool stopping_ = false;

  // statistics
  LatencyHistogram step_hist_, late_hist_;      // this health window
  LatencyHistogram step_total_, late_total_;    // whole run (final report)
  std::int64_t publish_failures_ = 0, nonfinite_blocked_ = 0, alarm_events_ = 0;
  std::int64_t publish_attempts_ = 0;
  bool fault_injected_ = false;
  std::int64_t cage_seq_ = 0, alarm_id_ = 0;
  LogRateLimiter<kRejectReasons + 3> reject_log_{5};  // + domain error, publish, alarm commands

  // preallocated messages and encode buffers
  hoist::winder_t winder_in_;
  hoist::cage_state_t cage_msg_;
  hoist::guide_shape_t shape_msg_;
  hoist::alarm_t alarm_msg_;
  hoist::health_t health_msg_;
  std::vector<std::uint8_t> cage_buf_, shape_buf_, alarm_buf_, health_buf_;
  char text_[256];
};

}  // namespace hoist::svc
