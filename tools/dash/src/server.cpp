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
#include <utility>
#include <spdlog/spdlog.h>

#include "hoist/msg/codec.hpp"
#include "log_safe.hpp"

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
  WsSession(tcp::socket&& s, Server& server, std::string peer_addr, bool authenticated)
      : ws_(std::move(s)), server_(server) {
    peer_key = std::move(peer_addr);
    authed = authenticated;
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
  HttpSession(tcp::socket&& s, Server& server, std::string peer_addr, bool on_probation)
      : stream_(std::move(s)), server_(server) {
    peer_key = std::move(peer_addr);
    probation = on_probation;
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
    stream_.expires_after(std::chrono::seconds(probation ? 2 : 30));
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
      const std::string shown = logSafe(sv(req[http::field::host]), 80);
      if (server_.logAllowed())
        spdlog::warn("{} with Host '{}' refused: not a name of this dashboard (see --allow-host)",
                     ws ? "WebSocket" : "HTTP request", shown);
      respondError(http::status::forbidden,
                   "Host '" + shown + "' is not a name of this dashboard (hoist-dash --allow-host)", false);
      return;
    }
    // The token: an authenticated client has the reserve; one on probation
    // (admitted beyond its peer's limits) must present it.
    const std::string_view presented = Server::presentedToken(
        sv(req[http::field::authorization]), sv(req[http::field::cookie]), sv(req.target()));
    if (!authed && server_.tokenMatches(presented)) {
      server_.promote(this);
      // Opened with ?token=: the browser keeps it as a cookie for the WebSocket.
      if (sv(req.target()).find("token=") != std::string_view::npos)
        set_cookie_ = std::string(Server::kTokenCookie) + "=" + std::string(presented) +
                      "; Path=/; HttpOnly; SameSite=Strict";
    }
    if (probation && !authed) {
      hub.count("http_rejected_probation_unauthenticated");
      respondError(http::status::too_many_requests,
                   "too many connections from your address; clients with the dashboard's token have a reserve "
                   "(docs/security.md)", false);
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
                       logSafe(sv(origin), 120));
        respondError(http::status::forbidden, "origin not allowed (hoist-dash --allow-origin)", false);
        return;
      }
    }
    if (!server_.admitWebSocket(peer_key, authed)) {
      hub.count("ws_rejected_too_many_clients");
      respondError(http::status::service_unavailable, "too many clients", false);
      return;
    }
    stream_.expires_never();
    // The connection moves to the WebSocket session: counted once, there.
    server_.untrack(this);
    released_ = true;
    std::make_shared<WsSession>(stream_.release_socket(), server_, peer_key, authed)->run(std::move(req));
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
    if (target == "/api/condition") {  // the "Shaft condition" view (condition.hpp)
      if (!server_.conditionProvider()) {
        // Not an error: the view is off.  (A 404 here was a console error
        // on every page of a dashboard started without --history.)
        respond(http::status::ok,
                R"j({"enabled":false,"why":"no history database (hoist-dash --history URL)"})j",
                "application/json", req.keep_alive(), req.method() == http::verb::head);
        return;
      }
      respond(http::status::ok, server_.conditionProvider()(), "application/json", req.keep_alive(),
              req.method() == http::verb::head);
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
        spdlog::warn("refused path traversal: {}", logSafe(target));
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
    if (!set_cookie_.empty()) res->set(http::field::set_cookie, std::exchange(set_cookie_, std::string()));
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
  std::string set_cookie_;  // sent with the next response (the token, opened with ?token=)
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
      const Admission a = admit(peer);
      if (a == Admission::Refused) {
        beast::error_code ignore;
        s.shutdown(tcp::socket::shutdown_both, ignore);
        s.close(ignore);
      } else {
        std::make_shared<HttpSession>(std::move(s), *this, peer, a == Admission::Probation)->run();
      }
    }
    doAccept();
  });
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
