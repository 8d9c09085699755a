// hoist-dash's Host and Origin checks (Server's members; DNS rebinding and
// cross-site WebSocket hijacking, docs/security.md "The dashboard"): which
// names this server answers to, and which browser pages may open its
// WebSocket.  Pure string checks, called by the HTTP session (server.cpp).
#include <cctype>

#include "server.hpp"

namespace hoist::dash {

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

}  // namespace hoist::dash
