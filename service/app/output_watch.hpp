// The output watch of hoist-twind: with [service] lcm_url_out elsewhere the
// input socket cannot see a second publisher of our outputs, so a
// receive-only socket on the output group watches our own HOIST_HEALTH (and
// HOIST_ALARM) channels: another instance_id there is DUPLICATE_PUBLISHER
// (ShaftInputs::watchOwnOutputs).  Dispatch is by exact name, nothing stored
// per name; a kernel filter drops every datagram but the HOIST_HEALTH
// channels where it can, so the loop does not wake for its own cage and
// shape messages (the point of lcm_url_out).
//
// Who calls: Daemon (daemon.hpp) owns one; open() in start() when
// lcm_url_out is set, stop() when the loop stops.  The readable handler runs
// on the loop thread and drains at most 256 datagrams per wake-up.  A URL
// that is not udpm://, or a socket that cannot be opened, is logged (a
// warning) and the watch stays off: detection is lost, the daemon runs on.
//
// Lifetimes: the io_context, the RtLog, the logger and the shafts are the
// Daemon's and outlive the watch.  The descriptor belongs to the receiver:
// the watch releases it from Asio (never closes it) in stop() and its
// destructor.
#pragma once

#include <utility>  // before Asio: Boost 1.74 awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <memory>
#include <spdlog/spdlog.h>
#include <string>
#include <vector>

#include "hoist/bus/udpm_receiver.hpp"
#include "hoist/rt/rt_log.hpp"

namespace hoist::service::inline app {

class ShaftTwin;

class OutputWatch {
 public:
  OutputWatch(boost::asio::io_context& io, rt::RtLog& log, std::shared_ptr<spdlog::logger> out)
      : log_(log), out_(std::move(out)), fd_(io) {}
  ~OutputWatch();
  OutputWatch(const OutputWatch&) = delete;
  OutputWatch& operator=(const OutputWatch&) = delete;

  /// Opens the receive-only socket on `url` ([service] lcm_url_out), routes
  /// each shaft's own output channels to it and arms the readable handler;
  /// warns and stays off when it cannot.
  void open(const std::string& url, const std::vector<std::unique_ptr<ShaftTwin>>& shafts);
  /// The loop stops: cancel the handler and release the descriptor.
  void stop();

 private:
  void arm();
  void onReadable(const boost::system::error_code& ec);

  rt::RtLog& log_;
  std::shared_ptr<spdlog::logger> out_;
  std::unique_ptr<bus::UdpmReceiver> receiver_;  ///< the socket on the output group (owns the descriptor)
  boost::asio::posix::stream_descriptor fd_;     ///< receiver_'s socket, watched by Asio
  bool stopped_ = false;
};

}  // namespace hoist::service::app
