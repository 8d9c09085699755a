// hoist-dash -- the live shaft dashboard: a web page and a Foxglove WebSocket
// protocol server (subprotocol foxglove.websocket.v1) on one port, fed by the
// hoist LCM channels of one or several shafts.  See docs/dashboard.md.
//
//   hoist-dash [--bind ADDR] [--port N] [--read-only] [--channel-prefix P]...
//              [--lcm-url URL] [--web-root DIR] [--warning-fraction F] ...
//
// One thread, one Asio loop: the LCM file descriptor, the HTTP/WebSocket
// server (Boost.Beast) and the 25 Hz decimation timer.
#include "hoist/cli/app.hpp"
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <boost/asio.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/msg/codec.hpp"
#include "src/condition.hpp"
#include "src/credential.hpp"
#include "src/hub.hpp"
#include "src/server.hpp"
#include "src/static_files.hpp"

namespace {

namespace net = boost::asio;
using hoist::dash::Hub;
using hoist::dash::Json;

std::uint64_t wallNs() {
  using namespace std::chrono;
  return static_cast<std::uint64_t>(duration_cast<nanoseconds>(system_clock::now().time_since_epoch()).count());
}

std::string defaultWebRoot() {
  // <prefix>/bin/hoist-dash -> <prefix>/share/hoist-twin/dash (build and install tree alike)
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "share/hoist-twin/dash";
  return (exe.parent_path().parent_path() / "share" / "hoist-twin" / "dash").string();
}

struct LcmPump {
  lcm::LCM* lcm;
  Hub* hub;
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    // Never let anything escape into LCM's C dispatch loop.
    try {
      hub->onLcm(channel, rbuf->data, rbuf->data_size);
    } catch (const std::exception& e) {
      hub->count("lcm_handler_exceptions");
      spdlog::error("LCM message on {}: {}", hoist::msg::terminalSafe(channel, 64), e.what());
    } catch (...) {
      hub->count("lcm_handler_exceptions");
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-dash: the live shaft dashboard.  Serves a web page and the Foxglove WebSocket protocol\n"
      "(subprotocol foxglove.websocket.v1) on one port, with every hoist LCM channel of every shaft\n"
      "advertised under its LCM channel name in JSON encoding.  Binds loopback by default: anyone who\n"
      "can reach the port can acknowledge and shelve alarms unless --read-only (docs/security.md)."};
  hoist::cli::nameProgram(app, "hoist-dash");  // usage, errors and --version name the program
  std::string bind = "127.0.0.1", url, web_root, log_level = "info";
  int port = 8080;
  bool read_only = false;
  std::vector<std::string> prefixes, origins, allow_hosts;
  double warning_fraction = 0.5, critical_fraction = 0.8;
  double rate = 25.0, duration = 0.0;
  std::size_t max_clients = 64, max_msg = 64 * 1024, max_queue_kb = 2048, max_per_peer = 32;
  double command_rate = 2.0, command_burst = 10.0;
  double max_peer_rate = 30.0;
  std::string token_credential = "hoist-dash-token";
  std::size_t reserved = 4;
  std::string history_url, history_config, history_shaft;
  double history_poll = 2.0;
  app.add_option("--bind", bind, "address to listen on (default 127.0.0.1: this machine only)");
  app.add_option("--port", port, "TCP port (default 8080; 0 = any free port, printed at start-up)")
      ->check(CLI::Range(0, 65535));
  app.add_flag("--read-only", read_only, "no operator commands: no Acknowledge/Shelve buttons, "
                                         "client publishing refused");
  app.add_option("--channel-prefix", prefixes,
                 "shaft channel prefix (repeatable; '' is the default shaft); default: discover the "
                 "prefixes from the *HOIST_HEALTH channels");
  app.add_option("--warning-fraction", warning_fraction,
                 "WARNING level as a fraction of the gap, for the clearance thresholds drawn until the daemon's "
                 "first alarm tells (default 0.5, hoist-twind's default [alarms] warning_fraction)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--critical-fraction", critical_fraction, "CRITICAL level likewise (default 0.8)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  app.add_option("--web-root", web_root, "directory of the page (default: <prefix>/share/hoist-twin/dash)");
  app.add_option("--rate", rate, "display rate of the decimated cage channel [Hz] (default 25)")
      ->check(CLI::Range(1.0, 100.0));
  app.add_option("--max-clients", max_clients, "WebSocket clients at a time (default 64)")
      ->check(CLI::Range(1, 10000));
  app.add_option("--max-per-peer", max_per_peer,
                 "connections (HTTP and WebSocket) at a time from one remote address (default 32); a newcomer "
                 "is never refused while one address holds more than its share of the connections")
      ->check(CLI::Range(1, 10000));
  app.add_option("--max-peer-rate", max_peer_rate,
                 "new connections a second from one remote address (default 30, bursts of twice that)")
      ->check(CLI::Range(1.0, 100000.0));
  auto* tok_opt = app.add_option("--token-credential", token_credential,
                 "name of the systemd credential (LoadCredential=NAME:FILE; read from $CREDENTIALS_DIRECTORY/NAME) "
                 "holding the token of authenticated clients (default hoist-dash-token; used when present). "
                 "Clients presenting it (Authorization: Bearer, or the page opened once as /?token=...) have "
                 "--reserved-clients of their own and are never closed to make room for others");
  app.add_option("--reserved-clients", reserved,
                 "WebSockets kept for clients with the token, beyond --max-clients (default 4)")
      ->check(CLI::Range(0, 1000));
  app.add_option("--command-rate", command_rate,
                 "operator commands a second from one client (default 2, bursts of --command-burst); beyond "
                 "it a command is refused and counted (commands_rejected_rate)")
      ->check(CLI::Range(0.01, 1000.0));
  app.add_option("--command-burst", command_burst, "commands one client may send at once (default 10)")
      ->check(CLI::Range(1.0, 10000.0));
  app.add_option("--max-message", max_msg, "largest accepted WebSocket message [bytes] (default 65536)")
      ->check(CLI::Range(64, 16 * 1024 * 1024));
  app.add_option("--max-queue-kb", max_queue_kb, "send queue per client before data is dropped [KiB] (default 2048)")
      ->check(CLI::Range(16, 1024 * 1024));
  app.add_option("--allow-origin", origins,
                 "also accept WebSocket connections from pages of this origin (repeatable; '*' = any). "
                 "Default: only the dashboard's own page and non-browser clients");
  app.add_option("--allow-host", allow_hosts,
                 "also answer requests whose Host header names this host name or address (repeatable; no port: "
                 "the port is not compared). Default: the --bind address, localhost, and 127.0.0.1 and ::1 when "
                 "bound to loopback or to all addresses. Any other Host gets 403 (DNS rebinding)");
  app.add_option("--duration", duration, "stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  // The "Shaft condition" view (src/condition.hpp, docs/dashboard.md).
  app.add_option("--history", history_url,
                 "trip history database, read only: a SQLite file (sqlite:///path or a path) or postgresql://...; "
                 "enables the Shaft condition view (default: none, or --config's [history] url)");
  app.add_option("--config", history_config,
                 "hoist-twind's configuration: its [history] url (unless --history) and password, and its "
                 "[condition] thresholds for the Shaft condition view");
  app.add_option("--history-shaft", history_shaft, "the shaft's name in the history database (default: the default shaft, \"\")");
  app.add_option("--history-poll", history_poll, "seconds between checks of the history database for new trips (default 2)")
      ->check(CLI::Range(0.1, 3600.0));
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  spdlog::set_default_logger(spdlog::stderr_color_mt("hoist-dash"));
  spdlog::set_level(spdlog::level::from_str(log_level));
  spdlog::set_pattern("%Y-%m-%d %H:%M:%S.%e [%^%l%$] hoist-dash: %v");

  Hub::Options opt;
  opt.read_only = read_only;
  opt.command_rate = command_rate;
  opt.command_burst = command_burst;
  Json meta = Json::object();
  meta["*"] = Json{{"warning_fraction", warning_fraction}, {"critical_fraction", critical_fraction}};
  for (const auto& p : prefixes) {
    if (p.size() > 64 || p.find_first_of(" \t\r\n") != std::string::npos) {
      std::fprintf(stderr, "hoist-dash: --channel-prefix '%s': at most 64 characters, no white space\n", p.c_str());
      return 2;
    }
  }
  opt.prefixes = prefixes;
  opt.discover = prefixes.empty();
  opt.shaft_meta = meta;

  boost::system::error_code ec;
  const auto addr = net::ip::make_address(bind, ec);
  if (ec) {
    std::fprintf(stderr, "hoist-dash: --bind %s: not an IP address (%s)\n", bind.c_str(), ec.message().c_str());
    return 2;
  }
  // The names this dashboard answers to (server.hpp: Limits::allowed_hosts).
  std::vector<std::string> hosts{"localhost"};
  auto addHost = [&hosts](const std::string& h) {
    if (std::find(hosts.begin(), hosts.end(), h) == hosts.end()) hosts.push_back(h);
  };
  if (!addr.is_unspecified()) addHost(addr.to_string());
  if (addr.is_loopback() || addr.is_unspecified()) {
    addHost("127.0.0.1");
    addHost("::1");
  }
  for (const auto& h : allow_hosts) {
    // An address (IPv6 with or without brackets), or a host name without a port.
    boost::system::error_code aec;
    std::string inner = h.size() > 2 && h.front() == '[' && h.back() == ']' ? h.substr(1, h.size() - 2) : h;
    const auto a = net::ip::make_address(inner, aec);
    const std::string norm = aec ? hoist::dash::Server::hostOfHeader(h) : a.to_string();
    if (norm.empty() || (aec && h.find_first_of(":[]") != std::string::npos)) {
      std::fprintf(stderr,
                   "hoist-dash: --allow-host '%s': not a host name or IP address (give the name without a port, "
                   "IPv6 as ::1 or [::1])\n",
                   h.c_str());
      return 2;
    }
    addHost(norm);
  }
  if (addr.is_unspecified() && allow_hosts.empty())
    spdlog::warn("--bind {}: only requests addressed to localhost, 127.0.0.1 or ::1 are answered; add "
                 "--allow-host NAME for each name or address operators use to reach this machine",
                 bind);
  if (web_root.empty()) web_root = defaultWebRoot();
  std::unique_ptr<hoist::dash::StaticFiles> files;
  try {
    files = std::make_unique<hoist::dash::StaticFiles>(web_root);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hoist-dash: %s\n", e.what());
    return 2;
  }

  std::unique_ptr<hoist::dash::ConditionView> condition;
  if (!history_url.empty() || !history_config.empty()) {
    hoist::dash::ConditionOptions co;
    try {
      co = hoist::dash::conditionOptions(history_url, history_config, history_shaft);
    } catch (const std::exception& e) {  // std::invalid_argument, io::ConfigError: both name the option / key
      std::fprintf(stderr, "hoist-dash: %s\n", e.what());
      return 2;
    }
    co.poll_s = history_poll;
    // A missing or bad database is not fatal: the view says why and the worker retries.
    condition = std::make_unique<hoist::dash::ConditionView>(std::move(co));
  }

  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-dash", app.count("--lcm-url") > 0, url, hoist::bus::resolveLcmUrl(url)); !bad.empty()) { std::fprintf(stderr, "%s\n", bad.c_str()); return 2; }
  url = hoist::bus::resolveLcmUrl(url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "hoist-dash: cannot open LCM at %s\n", hoist::bus::describeLcmUrl(url).c_str());
    return 1;
  }

  Hub hub(
      opt,
      [&lcm](const std::string& ch, const std::vector<std::uint8_t>& b) {
        return lcm.publish(ch, b.data(), static_cast<unsigned>(b.size())) == 0;
      },
      wallNs);
  LcmPump pump{&lcm, &hub};
  // The receive path for the URL (our own for udpm://, LCM's otherwise:
  // hoist/bus/subscriber.hpp); LCM's ".*HOIST_.*" (anchored): any name containing HOIST_.
  hoist::bus::Subscriber rx(lcm);
  std::string rx_why;
  if (!rx.open(url, rx_why)) {
    std::fprintf(stderr, "hoist-dash: %s\n", rx_why.c_str());
    return 1;
  }
  rx.addMatching([](std::string_view n) { return n.find("HOIST_") != std::string_view::npos; }, ".*HOIST_.*",
                 [&pump](const lcm::ReceiveBuffer* rb, const std::string& ch) { pump.onMessage(rb, ch); });
  hub.requestAlarmStates();  // alarms raised before this start: their states now

  net::io_context io;
  hoist::dash::Server::Limits lim;
  lim.max_connections = max_clients;
  lim.max_ws_message = max_msg;
  lim.max_queue_bytes = max_queue_kb * 1024;
  lim.allowed_origins = origins;
  lim.allowed_hosts = hosts;
  lim.max_per_peer = max_per_peer;
  lim.max_attempts_per_s = max_peer_rate;
  {
    const hoist::dash::Credential cred = hoist::dash::readCredential(token_credential);
    if (!cred.error.empty()) {
      std::fprintf(stderr, "hoist-dash: --token-credential %s: %s\n", token_credential.c_str(), cred.error.c_str());
      return 2;
    }
    if (!cred.found && tok_opt->count() > 0) {
      std::fprintf(stderr, "hoist-dash: --token-credential %s: no such credential ($CREDENTIALS_DIRECTORY/%s; "
                           "systemd's LoadCredential=%s:FILE)\n", token_credential.c_str(), token_credential.c_str(),
                   token_credential.c_str());
      return 2;
    }
    lim.token = cred.value;
    lim.reserved = reserved;
    if (cred.found)
      spdlog::info("authenticated clients: token from credential '{}'; {} WebSocket(s) reserved for them",
                   token_credential, reserved);
  }
  hoist::dash::Server server(io, hub, *files, lim);
  if (condition) server.setConditionProvider([&condition] { return condition->snapshot(); });
  try {
    server.listen({addr, static_cast<unsigned short>(port)});
  } catch (const boost::system::system_error& e) {
    std::fprintf(stderr, "hoist-dash: cannot listen on %s:%d: %s\n", bind.c_str(), port, e.code().message().c_str());
    return 1;
  }

  // LCM: its socket in the same loop.
  net::posix::stream_descriptor lcm_fd(io, ::dup(rx.fd()));
  std::function<void()> waitLcm = [&]() {
    lcm_fd.async_wait(net::posix::stream_descriptor::wait_read, [&](boost::system::error_code e) {
      if (e) return;
      rx.drain(1000);
      waitLcm();
    });
  };
  waitLcm();

  // Decimated channels at the display rate.
  net::steady_timer tick(io);
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / rate));
  auto next = std::chrono::steady_clock::now() + period;
  std::function<void()> waitTick = [&]() {
    tick.expires_at(next);
    tick.async_wait([&](boost::system::error_code e) {
      if (e) return;
      hub.flushDecimated();
      next += period;
      const auto now = std::chrono::steady_clock::now();
      if (next < now) next = now + period;
      waitTick();
    });
  };
  waitTick();

  // Stop by closing everything: io.run() returns once the sessions' handlers
  // have run (a forced io.stop() would leave sessions to die after the server).
  net::signal_set signals(io, SIGINT, SIGTERM);
  net::steady_timer end_timer(io);
  auto stopAll = [&]() {
    server.stop();
    tick.cancel();
    lcm_fd.cancel();
    signals.cancel();
    end_timer.cancel();
  };
  signals.async_wait([&](boost::system::error_code e, int) {
    if (!e) stopAll();
  });
  if (duration > 0.0) {
    end_timer.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(duration)));
    end_timer.async_wait([&](boost::system::error_code e) {
      if (!e) stopAll();
    });
  }
  std::signal(SIGPIPE, SIG_IGN);

  const std::string shown = addr.is_v6() ? "[" + bind + "]" : bind;
  std::printf("hoist-dash: serving http://%s:%u/ (LCM %s, %s, shafts: %s)\n", shown.c_str(), server.port(),
              hoist::bus::describeLcmUrl(url).c_str(), read_only ? "read-only" : "operator commands enabled",
              prefixes.empty() ? "discovered from *HOIST_HEALTH" : Json(prefixes).dump().c_str());
  std::fflush(stdout);
  if (!addr.is_loopback())
    spdlog::warn("listening on {}: anyone who reaches this port can {}", bind,
                 read_only ? "watch the shaft" : "acknowledge and shelve alarms (consider --read-only)");

  io.run();
  io.restart();
  io.run_for(std::chrono::seconds(1));  // anything still completing
  spdlog::info("stopped; counters: {}", hub.stats()["counters"].dump());
  return 0;
}
