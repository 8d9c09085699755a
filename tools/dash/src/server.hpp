// hoist/dash server.hpp -- HTTP and WebSocket on one port with Boost.Beast.
//
// GET serves the page's files (StaticFiles), /api/stats (the Hub's
// counters as JSON) and /api/condition (the Shaft condition view's snapshot,
// setConditionProvider); a WebSocket upgrade that offers the subprotocol
// foxglove.websocket.v1 becomes a protocol client of the Hub.  Everything runs
// on the one io_context thread.  Limits: request header 8 KiB and no request
// body, 30 s to send a request, at most `max_connections` WebSockets and twice
// that in connections, per peer (remote address) at most `max_per_peer`
// connections and `max_attempts_per_s` new ones a second, with a reserve: a
// newcomer is never refused while another peer holds more than its fair
// share (that peer's oldest connection is closed instead), a peer being
// one remote address, all of loopback (127.0.0.0/8 and ::1) or an IPv6 /64;
// clients that present the token (Limits::token) have a reserved share and
// are never closed to make room for others (admission.cpp); incoming
// WebSocket messages at most `max_ws_message` bytes, and a bounded send queue
// per client: data frames beyond `max_queue_bytes` are dropped (counted),
// a client whose control frames overflow twice that is disconnected.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "hoist/rt/token_bucket.hpp"
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
    /// Host names and addresses this server answers to (lower case, IPv6
    /// without brackets, no port).  A request whose Host header names
    /// anything else gets 403, HTTP and WebSocket alike (DNS rebinding).
    /// Empty: every Host is accepted (unit tests only; main.cpp always sets it).
    std::vector<std::string> allowed_hosts;
    /// Per peer (remote address): connections (HTTP and WebSocket) at a
    /// time, and new connections per second (a token bucket of twice that).
    std::size_t max_per_peer = 32;
    double max_attempts_per_s = 30.0;
    /// Clients that present this token (Authorization: Bearer, the cookie
    /// kTokenCookie, or ?token= which sets the cookie) are authenticated:
    /// they count against no peer's cap or share, are never closed to make
    /// room, and have `reserved` WebSockets of their own beyond the table
    /// (and up to `reserved` connections on probation).  "" = none.
    std::string token;
    std::size_t reserved = 4;
  };
  static constexpr std::string_view kTokenCookie = "hoist_dash_token";
  /// The token a request presents ("" none): its Authorization: Bearer, its
  /// cookie kTokenCookie, or its target's ?token=.
  static std::string_view presentedToken(std::string_view authorization, std::string_view cookie,
                                         std::string_view target);
  /// Is `presented` the configured token?  (Constant time; false with none.)
  bool tokenMatches(std::string_view presented) const;
  /// The host part of a Host header value, lower case, without brackets,
  /// port or trailing dot; "" when the value is malformed (a bad port, an
  /// unclosed bracket, characters no host name has).
  static std::string hostOfHeader(std::string_view host);
  /// Is this Host header value one of limits().allowed_hosts?  (The port is
  /// not compared: a tunnel or proxy may change it, a rebinding attack
  /// changes the name.)
  bool hostAllowed(std::string_view host_header) const;
  /// Is this Origin header value allowed for a request with this (allowed)
  /// Host header: the page's own ("http(s)://" + Host) or --allow-origin?
  bool originAllowed(std::string_view origin, std::string_view host_header) const;
  Server(boost::asio::io_context& io, Hub& hub, const StaticFiles& files, Limits limits);
  ~Server();
  /// Binds and listens; throws boost::system::system_error (e.g. port in use).
  void listen(const boost::asio::ip::tcp::endpoint& ep);
  unsigned short port() const;
  void stop();  ///< closes the acceptor and every connection
  /// GET /api/condition answers with what `provider` returns (JSON text; it
  /// runs on the I/O thread: it must not block, e.g. ConditionView::snapshot).
  /// Unset: 404 naming --history.
  void setConditionProvider(std::function<std::string()> provider) { condition_ = std::move(provider); }
  const std::function<std::string()>& conditionProvider() const { return condition_; }

  // Used by the sessions.
  struct Conn {
    virtual ~Conn() = default;
    virtual void shutdown() = 0;
    /// An HTTP connection waiting for (the rest of) a request: may be
    /// closed to make room.  WebSockets and HTTP answers in flight are not idle.
    virtual bool idle() const = 0;
    std::string peer_key;    ///< peer (peerOf: an address, "loopback" or an IPv6 /64; "" unknown)
    bool ws = false;         ///< a WebSocket session
    bool authed = false;     ///< presented the token (promote())
    bool probation = false;  ///< admitted beyond its peer's limits: must authenticate in its first request
    std::uint64_t seq = 0;   ///< accept order (oldest first when evicting)
  };
  Hub& hub() { return hub_; }
  const StaticFiles& files() const { return files_; }
  const Limits& limits() const { return limits_; }
  void track(Conn* c);
  void untrack(Conn* c);
  std::size_t connections() const { return conns_.size(); }
  std::size_t wsConnections(bool authed = false) const;
  /// A connection presented the token: from now on it is authenticated.
  void promote(Conn* c);
  /// A WebSocket upgrade from `peer`: true if there is room (making room by
  /// closing the oldest WebSocket of a peer holding more than its share);
  /// an authenticated one has the reserve.
  bool admitWebSocket(const std::string& peer, bool authed);
  /// The peer key of an address: IPv4-mapped IPv6 as IPv4; "loopback" for
  /// 127.0.0.0/8 and ::1; "a:b:c:d::/64" for any other IPv6 address; else
  /// the IPv4 address.
  static std::string peerOf(const boost::asio::ip::address& a);
  /// Rate limit of refusal log lines: at most 10 per 10 s (the rest counted).
  bool logAllowed();

 private:
  void doAccept();
  enum class Admission { Refused, Admitted, Probation };
  Admission admit(const std::string& peer);  ///< a new TCP connection: rate, per-peer cap, reserve
  /// Closes the oldest connection of `peer` (idle HTTP first; WebSockets only
  /// if `ws_too`); false if it has none to close.
  bool evictOldest(const std::string& peer, bool ws_only, bool ws_too);
  /// The peer with the most connections (WebSockets only if `ws_only`) when
  /// that is more than its fair share of `cap` among the peers present plus
  /// `newcomer`; "" if none.
  std::string overShare(const std::string& newcomer, std::size_t cap, bool ws_only) const;
  struct Peer {
    std::size_t conns = 0;
    std::optional<rt::TokenBucket> attempts;  // new connections a second (--max-peer-rate), from the first
  };
  std::map<std::string, Peer> peers_;  // unauthenticated connections by peer
  std::size_t authed_ = 0, probation_ = 0;
  std::uint64_t next_seq_ = 0;
  boost::asio::io_context& io_;
  Hub& hub_;
  const StaticFiles& files_;
  Limits limits_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::set<Conn*> conns_;
  std::function<std::string()> condition_;
  bool stopped_ = false;
  std::chrono::steady_clock::time_point log_window_{};
  std::size_t log_lines_ = 0, log_suppressed_ = 0;
};

}  // namespace hoist::dash
