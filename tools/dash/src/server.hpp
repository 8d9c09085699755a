// hoist/dash server.hpp -- HTTP and WebSocket on one port with Boost.Beast.
//
// GET serves the page's files (StaticFiles) and /api/stats (the Hub's
// counters as JSON); a WebSocket upgrade that offers the subprotocol
// foxglove.websocket.v1 becomes a protocol client of the Hub.  Everything runs
// on the one io_context thread.  Limits: request header 8 KiB and no request
// body, 30 s to send a request, at most `max_connections` at a time, incoming
// WebSocket messages at most `max_ws_message` bytes, and a bounded send queue
// per client: data frames beyond `max_queue_bytes` are dropped (counted),
// a client whose control frames overflow twice that is disconnected.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <cstddef>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "hub.hpp"
#include "static_files.hpp"

namespace hoist::dash {

class Server {
 public:
  struct Limits {
    std::size_t max_connections = 64;
    std::size_t max_ws_message = 64 * 1024;
    std::size_t max_queue_bytes = 2 * 1024 * 1024;
    std::size_t max_queue_frames = 1024;
    std::vector<std::string> allowed_origins;  ///< besides the page's own; "*" = any
  };
  Server(boost::asio::io_context& io, Hub& hub, const StaticFiles& files, Limits limits);
  ~Server();
  /// Binds and listens; throws boost::system::system_error (e.g. port in use).
  void listen(const boost::asio::ip::tcp::endpoint& ep);
  unsigned short port() const;
  void stop();  ///< closes the acceptor and every connection

  // Used by the sessions.
  struct Conn {
    virtual ~Conn() = default;
    virtual void shutdown() = 0;
  };
  Hub& hub() { return hub_; }
  const StaticFiles& files() const { return files_; }
  const Limits& limits() const { return limits_; }
  void track(Conn* c) { conns_.insert(c); }
  void untrack(Conn* c) { conns_.erase(c); }
  std::size_t connections() const { return conns_.size(); }

 private:
  void doAccept();
  boost::asio::io_context& io_;
  Hub& hub_;
  const StaticFiles& files_;
  Limits limits_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::set<Conn*> conns_;
  bool stopped_ = false;
};

}  // namespace hoist::dash
