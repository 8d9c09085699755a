// HTTP + WebSocket server of hoist-dash on Boost.Beast (see server.hpp).
#include "server.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>
#include <chrono>
#include <deque>
#include <spdlog/spdlog.h>

#include "hoist/msg/codec.hpp"

namespace hoist::dash {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

constexpr const char* kSubprotocol = "foxglove.websocket.v1";

std::string_view sv(beast::string_view v) { return {v.data(), v.size()}; }

// Does the comma-separated header value list contain `token`?
bool listHas(beast::string_view list, beast::string_view token) {
  std::size_t i = 0;
  while (i <= list.size()) {
    std::size_t j = list.find(',', i);
    if (j == beast::string_view::npos) j = list.size();
    beast::string_view item = list.substr(i, j - i);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (item == token) return true;
    i = j + 1;
  }
  return false;
}

void setCommonHeaders(http::response<http::string_body>& res) {
  res.set(http::field::server, "hoist-dash");
  res.set(http::field::cache_control, "no-cache");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("X-Frame-Options", "DENY");
  res.set("Content-Security-Policy",
          "default-src 'self'; style-src 'self' 'unsafe-inline'; connect-src 'self'; img-src 'self' data:");
}

// ---- WebSocket session -----------------------------------------------------------

class WsSession : public std::enable_shared_from_this<WsSession>, public Client, public Server::Conn {
 public:
  WsSession(tcp::socket&& s, Server& server, std::string peer_addr) : ws_(std::move(s)), server_(server) {
    peer_key = std::move(peer_addr);
    ws = true;
    server_.track(this);
  }
  bool idle() const override { return false; }
  ~WsSession() override {
    unregister();
    server_.untrack(this);
  }

  void run(http::request<http::string_body> req) {
    websocket::stream_base::timeout t{};
    t.handshake_timeout = std::chrono::seconds(10);
    t.idle_timeout = std::chrono::seconds(60);  // a ping after 30 s of silence, closed after 60 s
    t.keep_alive_pings = true;
    ws_.set_option(t);
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(http::field::server, "hoist-dash");
      res.set(http::field::sec_websocket_protocol, kSubprotocol);
    }));
    ws_.read_message_max(server_.limits().max_ws_message);
    ws_.auto_fragment(false);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
  }

  void sendText(std::shared_ptr<const std::string> frame) override { enqueue(std::move(frame), false, false); }
  void sendData(std::shared_ptr<const std::string> frame) override { enqueue(std::move(frame), true, true); }

  void shutdown() override {
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).close();
  }

 private:
  struct Out {
    std::shared_ptr<const std::string> data;
    bool binary;
  };

  void onAccept(beast::error_code ec) {
    if (ec) {
      server_.hub().count("ws_handshake_failed");
      return;
    }
    registered_ = true;
    server_.hub().addClient(*this);
    doRead();
  }

  void doRead() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    if (ec) {
      Hub& hub = server_.hub();
      if (ec == websocket::error::closed || ec == net::error::eof || ec == net::error::operation_aborted ||
          ec == net::error::connection_reset) {
        spdlog::debug("client {}: closed ({}: {})", peer(), ec.category().name(), ec.message());
      } else if (ec == websocket::error::message_too_big || ec == websocket::error::buffer_overflow) {
        hub.count("ws_rejected_oversized");
        spdlog::warn("client {}: message over {} bytes, closed (1009)", peer(), server_.limits().max_ws_message);
      } else if (ec == beast::error::timeout) {
        hub.count("ws_closed_timeout");
      } else if (ec == websocket::condition::protocol_violation ||
                 ec.category() == websocket::make_error_code(websocket::error::bad_opcode).category()) {
        hub.count("ws_rejected_malformed_frame");
        spdlog::warn("client {}: malformed WebSocket frame ({}), closed", peer(), ec.message());
      } else {
        hub.count("ws_closed_error");
      }
      unregister();
      return;
    }
    const auto data = in_.cdata();
    const std::string_view msg(static_cast<const char*>(data.data()), data.size());
    if (ws_.got_text()) server_.hub().onClientText(*this, msg);
    else server_.hub().onClientBinary(*this, msg);
    in_.consume(in_.size());
    doRead();
  }

  void enqueue(std::shared_ptr<const std::string> frame, bool binary, bool droppable) {
    if (closing_) return;
    const auto& lim = server_.limits();
    const std::size_t n = frame->size();
    if (droppable && (queued_bytes_ + n > lim.max_queue_bytes || queue_.size() >= lim.max_queue_frames)) {
      server_.hub().count("data_frames_dropped_slow_client");
      return;
    }
    if (queued_bytes_ + n > 2 * lim.max_queue_bytes || queue_.size() >= 2 * lim.max_queue_frames) {
      server_.hub().count("clients_closed_slow");
      spdlog::warn("client {}: send queue full ({} bytes), disconnected", peer(), queued_bytes_);
      closing_ = true;
      unregister();
      shutdown();
      return;
    }
    queued_bytes_ += n;
    queue_.push_back({std::move(frame), binary});
    if (!writing_) doWrite();
  }

  void doWrite() {
    writing_ = true;
    const Out& o = queue_.front();
    ws_.binary(o.binary);
    ws_.async_write(net::buffer(*o.data), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->onWrite(ec);
    });
  }

  void onWrite(beast::error_code ec) {
    writing_ = false;
    if (!queue_.empty()) {
      queued_bytes_ -= queue_.front().data->size();
      queue_.pop_front();
    }
    if (ec) {
      unregister();
      queue_.clear();
      queued_bytes_ = 0;
      return;
    }
    if (!queue_.empty() && !closing_) doWrite();
  }

  void unregister() {
    if (registered_) {
      registered_ = false;
      server_.hub().removeClient(*this);
    }
  }

  std::string peer() {
    beast::error_code ec;
    const auto ep = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    return ec ? std::string("?") : ep.address().to_string() + ":" + std::to_string(ep.port());
  }

  websocket::stream<beast::tcp_stream> ws_;
  Server& server_;
  beast::flat_buffer in_;
  std::deque<Out> queue_;
  std::size_t queued_bytes_ = 0;
  bool writing_ = false, registered_ = false, closing_ = false;
};

// ---- HTTP session ---------------------------------------------------------------

class HttpSession : public std::enable_shared_from_this<HttpSession>, public Server::Conn {
 public:
  HttpSession(tcp::socket&& s, Server& server, std::string peer_addr) : stream_(std::move(s)), server_(server) {
    peer_key = std::move(peer_addr);
    server_.track(this);
  }
  ~HttpSession() override {
    if (!released_) server_.untrack(this);
  }
  bool idle() const override { return reading_; }

  void run() { doRead(); }
  void shutdown() override {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.close();
  }

 private:
  void doRead() {
    reading_ = true;
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(0);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    reading_ = false;
    Hub& hub = server_.hub();
    if (ec == net::error::operation_aborted) return;  // closed by stop() or to make room
    if (ec == http::error::end_of_stream || ec == net::error::eof || ec == net::error::connection_reset) {
      shutdown();
      return;
    }
    if (ec == beast::error::timeout) {
      hub.count("http_closed_timeout");
      return;
    }
    if (ec) {
      hub.count("http_rejected_malformed");
      const bool big = ec == http::error::header_limit || ec == http::error::body_limit ||
                       ec == http::error::buffer_overflow;
      if (big) hub.count("http_rejected_oversized");
      respondError(big ? http::status::payload_too_large : http::status::bad_request,
                   "malformed or oversized HTTP request: " + ec.message(), false);
      return;
    }
    auto req = parser_->release();
    hub.count("http_requests");
    // DNS rebinding: a page of evil.example whose name was re-resolved to this
    // address is same-origin with evil.example in the browser, so its Origin
    // matches its Host.  Only the names this server is known by are answered.
    if (!server_.hostAllowed(sv(req[http::field::host]))) {
      const bool ws = websocket::is_upgrade(req);
      hub.count(ws ? "ws_rejected_host" : "http_rejected_host");
      const std::string shown = msg::terminalSafe(std::string(req[http::field::host]), 80);
      if (server_.logAllowed())
        spdlog::warn("{} with Host '{}' refused: not a name of this dashboard (see --allow-host)",
                     ws ? "WebSocket" : "HTTP request", shown);
      respondError(http::status::forbidden,
                   "Host '" + shown + "' is not a name of this dashboard (hoist-dash --allow-host)", false);
      return;
    }
    if (websocket::is_upgrade(req)) {
      upgrade(std::move(req));
      return;
    }
    handle(req);
  }

  void upgrade(http::request<http::string_body> req) {
    Hub& hub = server_.hub();
    const auto target = req.target();
    if (target != "/" && target != "/ws") {
      hub.count("ws_rejected_path");
      respondError(http::status::not_found, "WebSocket endpoint is / (or /ws)", false);
      return;
    }
    if (!listHas(req[http::field::sec_websocket_protocol], kSubprotocol)) {
      hub.count("ws_rejected_subprotocol");
      respondError(http::status::bad_request, "WebSocket subprotocol foxglove.websocket.v1 required", false);
      return;
    }
    // Cross-site WebSocket hijacking: a browser page from another origin must
    // not drive this server (it could acknowledge alarms).  The Host was
    // checked against the allow-list already (onRead), so "the page's own
    // origin" is one of the allowed names, not whatever name the browser used.
    const auto origin = req[http::field::origin];
    if (!origin.empty()) {
      if (!server_.originAllowed(sv(origin), sv(req[http::field::host]))) {
        hub.count("ws_rejected_origin");
        if (server_.logAllowed())
          spdlog::warn("WebSocket from origin {} refused (see --allow-origin)",
                       msg::terminalSafe(std::string(origin), 120));
        respondError(http::status::forbidden, "origin not allowed (hoist-dash --allow-origin)", false);
        return;
      }
    }
    if (!server_.admitWebSocket(peer_key)) {
      hub.count("ws_rejected_too_many_clients");
      respondError(http::status::service_unavailable, "too many clients", false);
      return;
    }
    stream_.expires_never();
    // The connection moves to the WebSocket session: counted once, there.
    server_.untrack(this);
    released_ = true;
    std::make_shared<WsSession>(stream_.release_socket(), server_, peer_key)->run(std::move(req));
  }

  void handle(const http::request<http::string_body>& req) {
    Hub& hub = server_.hub();
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      hub.count("http_rejected_method");
      respondError(http::status::method_not_allowed, "only GET and HEAD", req.keep_alive());
      return;
    }
    const std::string target(req.target());
    if (target == "/api/stats") {
      Json s = hub.stats();
      s["connections"] = server_.connections();
      respond(http::status::ok, s.dump(), "application/json", req.keep_alive(), req.method() == http::verb::head);
      return;
    }
    const StaticFile* f = nullptr;
    switch (server_.files().lookup(target, &f)) {
      case StaticFiles::Verdict::Found:
        hub.count("http_files_served");
        respond(http::status::ok, f->body, f->content_type, req.keep_alive(), req.method() == http::verb::head);
        return;
      case StaticFiles::Verdict::Traversal:
        hub.count("http_rejected_traversal");
        spdlog::warn("refused path traversal: {}", msg::terminalSafe(std::string(target), 200));
        respondError(http::status::forbidden, "path traversal refused", req.keep_alive());
        return;
      case StaticFiles::Verdict::BadRequest:
        hub.count("http_rejected_bad_target");
        respondError(http::status::bad_request, "bad request target", req.keep_alive());
        return;
      case StaticFiles::Verdict::NotFound:
        hub.count("http_not_found");
        respondError(http::status::not_found, "not found", req.keep_alive());
        return;
    }
  }

  void respondError(http::status st, const std::string& msg, bool keep_alive) {
    respond(st, msg + "\n", "text/plain; charset=utf-8", keep_alive, false);
  }

  void respond(http::status st, const std::string& body, const std::string& type, bool keep_alive, bool head) {
    auto res = std::make_shared<http::response<http::string_body>>(st, 11);
    setCommonHeaders(*res);
    res->set(http::field::content_type, type);
    res->keep_alive(keep_alive);
    if (!head) res->body() = body;
    res->content_length(body.size());
    stream_.expires_after(std::chrono::seconds(30));
    http::async_write(stream_, *res, [self = shared_from_this(), res, keep_alive](beast::error_code ec, std::size_t) {
      if (ec || !keep_alive) {
        self->shutdown();
        return;
      }
      self->doRead();
    });
  }

  beast::tcp_stream stream_;
  Server& server_;
  beast::flat_buffer buffer_{16 * 1024};
  std::optional<http::request_parser<http::string_body>> parser_;
  bool reading_ = false, released_ = false;
};

}  // namespace

Server::Server(net::io_context& io, Hub& hub, const StaticFiles& files, Limits limits)
    : io_(io), hub_(hub), files_(files), limits_(std::move(limits)), acceptor_(io) {}

Server::~Server() { stop(); }

void Server::listen(const tcp::endpoint& ep) {
  acceptor_.open(ep.protocol());
  acceptor_.set_option(net::socket_base::reuse_address(true));
  acceptor_.bind(ep);
  acceptor_.listen(net::socket_base::max_listen_connections);
  doAccept();
}

unsigned short Server::port() const { return acceptor_.local_endpoint().port(); }

void Server::doAccept() {
  acceptor_.async_accept(io_, [this](beast::error_code ec, tcp::socket s) {
    if (stopped_) return;
    if (!ec) {
      beast::error_code rec;
      const auto ep = s.remote_endpoint(rec);
      const std::string peer = rec ? std::string() : peerOf(ep.address());
      if (!admit(peer)) {
        beast::error_code ignore;
        s.shutdown(tcp::socket::shutdown_both, ignore);
        s.close(ignore);
      } else {
        std::make_shared<HttpSession>(std::move(s), *this, peer)->run();
      }
    }
    doAccept();
  });
}

std::string Server::peerOf(const net::ip::address& a) {
  if (a.is_v6() && a.to_v6().is_v4_mapped())
    return net::ip::make_address_v4(net::ip::v4_mapped, a.to_v6()).to_string();
  return a.to_string();
}

void Server::track(Conn* c) {
  c->seq = next_seq_++;
  conns_.insert(c);
  ++peers_[c->peer_key].conns;
}

void Server::untrack(Conn* c) {
  if (conns_.erase(c) == 0) return;
  const auto it = peers_.find(c->peer_key);
  if (it != peers_.end() && it->second.conns > 0) --it->second.conns;
}

std::size_t Server::wsConnections() const {
  std::size_t n = 0;
  for (const Conn* c : conns_) n += c->ws ? 1 : 0;
  return n;
}

bool Server::evictOldest(const std::string& peer, bool ws_only, bool ws_too) {
  Conn* best = nullptr;
  for (Conn* c : conns_) {
    if (c->peer_key != peer) continue;
    if (ws_only ? !c->ws : (c->ws ? !ws_too : !c->idle())) continue;
    // Idle HTTP before WebSockets, then the oldest.
    if (best == nullptr || (best->ws && !c->ws) || (best->ws == c->ws && c->seq < best->seq)) best = c;
  }
  if (best == nullptr) return false;
  untrack(best);  // its slot is free now, whenever its handlers run
  best->shutdown();
  return true;
}

std::string Server::overShare(const std::string& newcomer, std::size_t cap, bool ws_only) const {
  std::map<std::string, std::size_t> held;
  for (const Conn* c : conns_)
    if (!ws_only || c->ws) ++held[c->peer_key];
  if (held.empty()) return "";
  const std::size_t peers = held.size() + (held.count(newcomer) ? 0 : 1);
  const double share = static_cast<double>(cap) / static_cast<double>(peers);
  std::string top;
  std::size_t most = 0;
  for (const auto& [p, n] : held)
    if (n > most) {
      most = n;
      top = p;
    }
  const std::size_t mine = held.count(newcomer) ? held.at(newcomer) : 0;
  // Only a peer over its share, and holding more than the newcomer.
  if (static_cast<double>(most) > share && most > mine + 1 && top != newcomer) return top;
  return "";
}

bool Server::admit(const std::string& peer) {
  const auto now = std::chrono::steady_clock::now();
  if (peers_.size() > 4096) {  // forget peers with nothing open (bounded table)
    for (auto it = peers_.begin(); it != peers_.end();)
      it = it->second.conns == 0 ? peers_.erase(it) : std::next(it);
  }
  Peer& p = peers_[peer];
  const double burst = 2.0 * limits_.max_attempts_per_s;
  if (p.refilled.time_since_epoch().count() == 0) {
    p.tokens = burst;
  } else {
    p.tokens = std::min(burst, p.tokens + limits_.max_attempts_per_s *
                                             std::chrono::duration<double>(now - p.refilled).count());
  }
  p.refilled = now;
  if (p.tokens < 1.0) {
    hub_.count("http_rejected_peer_rate");
    if (logAllowed())
      spdlog::warn("connection from {} refused: more than {} new connections a second from that address", peer,
                   limits_.max_attempts_per_s);
    return false;
  }
  p.tokens -= 1.0;
  if (p.conns >= limits_.max_per_peer) {
    // At its cap: its own oldest idle HTTP connection makes room, else refused.
    if (!evictOldest(peer, false, false)) {
      hub_.count("http_rejected_peer_limit");
      if (logAllowed())
        spdlog::warn("connection from {} refused: it holds {} connections (--max-per-peer)", peer, p.conns);
      return false;
    }
    hub_.count("http_evicted_idle");
  }
  const std::size_t cap = 2 * limits_.max_connections;
  if (conns_.size() >= cap) {
    // The reserve: room for a newcomer as long as someone holds more than its share.
    const std::string hog = overShare(peer, cap, false);
    if (hog.empty() || !evictOldest(hog, false, true)) {
      hub_.count("http_rejected_too_many_connections");
      if (logAllowed()) spdlog::warn("connection from {} refused: {} connections open", peer, conns_.size());
      return false;
    }
    hub_.count("connections_evicted_over_share");
    if (logAllowed()) spdlog::warn("closed the oldest connection of {} (over its share) to admit {}", hog, peer);
  }
  return true;
}

bool Server::admitWebSocket(const std::string& peer) {
  if (wsConnections() < limits_.max_connections) return true;
  const std::string hog = overShare(peer, limits_.max_connections, true);
  if (hog.empty() || !evictOldest(hog, true, true)) return false;
  hub_.count("ws_evicted_over_share");
  if (logAllowed()) spdlog::warn("closed the oldest WebSocket of {} (over its share) to admit {}", hog, peer);
  return true;
}

std::string Server::hostOfHeader(std::string_view h) {
  std::string host;
  std::string_view rest;
  if (!h.empty() && h.front() == '[') {
    const auto close = h.find(']');
    if (close == std::string_view::npos) return "";
    host = std::string(h.substr(1, close - 1));
    rest = h.substr(close + 1);
    if (host.empty() || host.find_first_not_of("0123456789abcdefABCDEF:.") != std::string::npos) return "";
  } else {
    const auto colon = h.find(':');
    if (colon != std::string_view::npos && h.find(':', colon + 1) != std::string_view::npos) return "";  // bare IPv6
    host = std::string(h.substr(0, colon));
    rest = colon == std::string_view::npos ? std::string_view() : h.substr(colon);
    if (host.empty() || host.size() > 253 ||
        host.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-_") != std::string::npos)
      return "";
  }
  if (!rest.empty()) {
    if (rest.front() != ':' || rest.size() < 2 || rest.size() > 6 ||
        rest.substr(1).find_first_not_of("0123456789") != std::string_view::npos)
      return "";
  }
  for (char& c : host) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (host.size() > 1 && host.back() == '.') host.pop_back();
  return host;
}

bool Server::hostAllowed(std::string_view host_header) const {
  if (limits_.allowed_hosts.empty()) return true;
  const std::string h = hostOfHeader(host_header);
  if (h.empty()) return false;
  for (const auto& a : limits_.allowed_hosts)
    if (a == h) return true;
  return false;
}

bool Server::originAllowed(std::string_view origin, std::string_view host_header) const {
  for (const auto& a : limits_.allowed_origins)
    if (a == "*" || origin == a) return true;
  // The page's own origin: scheme + exactly the Host it was loaded from
  // (a page on another port of an allowed name is another origin).
  if (host_header.empty() || !hostAllowed(host_header)) return false;
  return origin == "http://" + std::string(host_header) || origin == "https://" + std::string(host_header);
}

bool Server::logAllowed() {
  const auto now = std::chrono::steady_clock::now();
  if (now - log_window_ > std::chrono::seconds(10)) {
    log_window_ = now;
    if (log_suppressed_ > 0) spdlog::warn("({} more refusals not logged in the last 10 s)", log_suppressed_);
    log_lines_ = log_suppressed_ = 0;
  }
  if (log_lines_ < 10) {
    ++log_lines_;
    return true;
  }
  ++log_suppressed_;
  return false;
}

void Server::stop() {
  if (stopped_) return;
  stopped_ = true;
  beast::error_code ec;
  acceptor_.close(ec);
  const std::set<Conn*> all = conns_;
  for (Conn* c : all) c->shutdown();
}

}  // namespace hoist::dash
