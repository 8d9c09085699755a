// hoist-dash's admission of connections (Server's members, apart from the
// HTTP and WebSocket sessions in server.cpp): peer groups, the per-peer cap
// and rate, the fair-share reserve of the connection and WebSocket tables,
// and the share kept for clients that authenticate with the token
// (docs/security.md, "The dashboard").
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cstdio>

#include "server.hpp"

namespace hoist::dash {

namespace net = boost::asio;

std::string Server::peerOf(const net::ip::address& a) {
  // One local process can bind any of 127.0.0.0/8 (and ::1), and one remote
  // host usually holds a whole IPv6 /64: each is one peer.
  if (a.is_v6() && a.to_v6().is_v4_mapped()) return peerOf(net::ip::make_address_v4(net::ip::v4_mapped, a.to_v6()));
  if (a.is_v4()) return a.to_v4().is_loopback() ? std::string("loopback") : a.to_string();
  const auto v6 = a.to_v6();
  if (v6.is_loopback()) return "loopback";
  const auto b = v6.to_bytes();
  char buf[48];
  std::snprintf(buf, sizeof buf, "%x:%x:%x:%x::/64", (b[0] << 8) | b[1], (b[2] << 8) | b[3], (b[4] << 8) | b[5],
                (b[6] << 8) | b[7]);
  return buf;
}

bool Server::tokenMatches(std::string_view presented) const {
  const std::string& t = limits_.token;
  if (t.empty() || presented.size() != t.size()) return false;
  unsigned char diff = 0;  // constant time over the token's length
  for (std::size_t i = 0; i < t.size(); ++i) diff |= static_cast<unsigned char>(t[i] ^ presented[i]);
  return diff == 0;
}

std::string_view Server::presentedToken(std::string_view authorization, std::string_view cookie,
                                        std::string_view target) {
  constexpr std::string_view kBearer = "Bearer ";
  if (authorization.substr(0, kBearer.size()) == kBearer) return authorization.substr(kBearer.size());
  // Cookie: a=b; hoist_dash_token=T; ...
  for (std::size_t at = 0; at < cookie.size();) {
    std::size_t end = cookie.find(';', at);
    if (end == std::string_view::npos) end = cookie.size();
    std::string_view kv = cookie.substr(at, end - at);
    while (!kv.empty() && kv.front() == ' ') kv.remove_prefix(1);
    if (kv.substr(0, kTokenCookie.size()) == kTokenCookie && kv.substr(kTokenCookie.size(), 1) == "=")
      return kv.substr(kTokenCookie.size() + 1);
    at = end + 1;
  }
  // ?token=T (the page opened once with it: the answer sets the cookie).
  const auto q = target.find('?');
  for (std::size_t at = q == std::string_view::npos ? target.size() : q + 1; at < target.size();) {
    std::size_t end = target.find('&', at);
    if (end == std::string_view::npos) end = target.size();
    const std::string_view kv = target.substr(at, end - at);
    if (kv.substr(0, 6) == "token=") return kv.substr(6);
    at = end + 1;
  }
  return {};
}

void Server::track(Conn* c) {
  c->seq = next_seq_++;
  conns_.insert(c);
  if (c->authed) ++authed_;
  else if (c->probation) ++probation_;
  else ++peers_[c->peer_key].conns;
}

void Server::untrack(Conn* c) {
  if (conns_.erase(c) == 0) return;
  if (c->authed) {
    --authed_;
  } else if (c->probation) {
    --probation_;
  } else if (const auto it = peers_.find(c->peer_key); it != peers_.end() && it->second.conns > 0) {
    --it->second.conns;
  }
}

void Server::promote(Conn* c) {
  if (c->authed || conns_.count(c) == 0) return;
  untrack(c);
  c->authed = true;
  c->probation = false;
  conns_.insert(c);
  ++authed_;
  hub_.count("clients_authenticated");
}

std::size_t Server::wsConnections(bool authed) const {
  std::size_t n = 0;
  for (const Conn* c : conns_) n += c->ws && c->authed == authed ? 1 : 0;
  return n;
}

bool Server::evictOldest(const std::string& peer, bool ws_only, bool ws_too) {
  Conn* best = nullptr;
  for (Conn* c : conns_) {
    if (c->peer_key != peer || c->authed || c->probation) continue;  // authenticated clients are never closed for others
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
    if (!c->authed && !c->probation && (!ws_only || c->ws)) ++held[c->peer_key];
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

Server::Admission Server::admit(const std::string& peer) {
  const auto now = std::chrono::steady_clock::now();
  if (peers_.size() > 4096) {  // forget peers with nothing open (bounded table)
    for (auto it = peers_.begin(); it != peers_.end();)
      it = it->second.conns == 0 ? peers_.erase(it) : std::next(it);
  }
  // Beyond the peer's limits or a full table, a connection may still come in
  // on probation while the reserve has room: its first request must carry
  // the token within 2 s, else it is closed (HttpSession).
  auto refuse = [&](const char* counter, const std::string& why) {
    if (!limits_.token.empty() && probation_ < limits_.reserved) {
      hub_.count("http_admitted_probation");
      return Admission::Probation;
    }
    hub_.count(counter);
    if (logAllowed()) spdlog::warn("connection from {} refused: {}", peer, why);
    return Admission::Refused;
  };
  Peer& p = peers_[peer];
  if (!p.attempts) p.attempts.emplace(limits_.max_attempts_per_s, 2.0 * limits_.max_attempts_per_s);
  if (!p.attempts->take(std::chrono::duration<double>(now.time_since_epoch()).count()))
    return refuse("http_rejected_peer_rate",
                  fmt::format("more than {} new connections a second from that peer", limits_.max_attempts_per_s));
  if (p.conns >= limits_.max_per_peer) {
    // At its cap: its own oldest idle HTTP connection makes room, else refused.
    if (!evictOldest(peer, false, false))
      return refuse("http_rejected_peer_limit", fmt::format("it holds {} connections (--max-per-peer)", p.conns));
    hub_.count("http_evicted_idle");
  }
  const std::size_t cap = 2 * limits_.max_connections;
  if (conns_.size() - authed_ - probation_ >= cap) {
    // The reserve: room for a newcomer as long as someone holds more than its share.
    const std::string hog = overShare(peer, cap, false);
    if (hog.empty() || !evictOldest(hog, false, true))
      return refuse("http_rejected_too_many_connections", fmt::format("{} connections open", conns_.size()));
    hub_.count("connections_evicted_over_share");
    if (logAllowed()) spdlog::warn("closed the oldest connection of {} (over its share) to admit {}", hog, peer);
  }
  return Admission::Admitted;
}

bool Server::admitWebSocket(const std::string& peer, bool authed) {
  if (authed) {
    // The reserve: `reserved` WebSockets beyond the table, and any room in it.
    const std::size_t mine = wsConnections(true);
    if (mine < limits_.reserved || mine + wsConnections(false) < limits_.max_connections) return true;
    hub_.count("ws_rejected_reserve_full");
    return false;
  }
  if (wsConnections(false) < limits_.max_connections) return true;
  const std::string hog = overShare(peer, limits_.max_connections, true);
  if (hog.empty() || !evictOldest(hog, true, true)) return false;
  hub_.count("ws_evicted_over_share");
  if (logAllowed()) spdlog::warn("closed the oldest WebSocket of {} (over its share) to admit {}", hog, peer);
  return true;
}

}  // namespace hoist::dash
