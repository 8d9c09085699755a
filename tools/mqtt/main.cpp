// hoist-mqtt -- bridge between the twin's LCM channels and an MQTT broker
// (SCADA, HMI, historian).  Topics, payloads, QoS and TLS: docs/mqtt.md.
//
//   hoist-mqtt --broker mqtt://HOST:PORT [--config FILE] [--no-commands]
//              [--channel-prefix P]... [--cage-rate HZ] [--client-id ID]
//              [--lcm-url URL] [--sparkplug GROUP/EDGE] [-q]
//
// Exit status: 0 after SIGINT/SIGTERM, 1 if LCM cannot be opened, 2 bad
// options or configuration.  A broker that is down or goes away is never
// fatal: the bridge retries with backoff.
#include "hoist/cli/app.hpp"
#include <mosquitto.h>

#include <csignal>
#include <iostream>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "hoist/bus/lcm_url.hpp"
#include "hoist/io/error.hpp"
#include "hoist/mqtt/bridge.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/journal.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hoist-mqtt: bridge the twin's LCM channels (cage state, health, alarms) to an MQTT broker, and "
               "operator alarm commands back (docs/mqtt.md)",
               "hoist-mqtt"};
  hoist::cli::nameProgram(app, "hoist-mqtt");  // usage, errors and --version name the program
  std::string config_path, broker, client_id, lcm_url, sparkplug;
  std::vector<std::string> prefixes;
  bool no_commands = false, quiet = false;
  double cage_rate = 0.0;
  app.add_option("--config", config_path, "TOML configuration: [broker] (URL, user, password file), [tls], [bridge], "
                                          "[buffer] (docs/mqtt.md)");
  app.add_option("--broker", broker, "broker URL mqtt://HOST:PORT or mqtts://HOST:PORT (default mqtt://127.0.0.1:1883, "
                                     "or [broker] url)");
  app.add_flag("--no-commands", no_commands, "do not subscribe to hoist/<shaft>/cmd/ack (read-only bridge)");
  app.add_option("--channel-prefix", prefixes,
                 "LCM channel prefix of a shaft (repeatable; MQTT shaft name = prefix without its trailing separator, "
                 "\"default\" for none); without it, shafts are discovered (a prefix is bridged once its daemon's health "
                 "keeps coming); a plant should list its shafts (docs/mqtt.md)");
  app.add_option("--cage-rate", cage_rate, "cage states per second per shaft (default 10, or [bridge] cage_rate)")
      ->check(CLI::Range(1e-3, 1000.0));
  app.add_option("--client-id", client_id, "MQTT client id (default hoist-mqtt-<hostname>)");
  app.add_option("--lcm-url", lcm_url, "LCM URL; default: $LCM_DEFAULT_URL, else [bridge] lcm_url, else LCM's default");
  app.add_option("--sparkplug", sparkplug,
                 "Sparkplug B mode as edge node EDGE of group GROUP (spBv1.0/GROUP/...; each shaft is a device) "
                 "instead of the JSON topics; or [sparkplug] in the configuration (docs/mqtt.md)");
  app.add_flag("-q,--quiet", quiet, "log warnings and errors only");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  spdlog::set_default_logger(spdlog::stderr_color_mt("hoist-mqtt"));  // logs on stderr (journal under systemd)
  spdlog::set_pattern("%Y-%m-%d %H:%M:%S.%e [%l] %v");
  if (quiet) spdlog::set_level(spdlog::level::warn);

  hoist::mqtt::BridgeConfig cfg;
  std::string password;
  try {
    if (!config_path.empty()) cfg = hoist::mqtt::loadBridgeConfig(config_path);
    // Command-line options override the file.
    if (!broker.empty()) cfg.url = broker;
    if (!client_id.empty()) cfg.client_id = client_id;
    if (!prefixes.empty()) cfg.channel_prefixes = prefixes;
    if (no_commands) cfg.commands = false;
    if (cage_rate > 0.0) cfg.cage_rate = cage_rate;
    if (!lcm_url.empty()) cfg.lcm_url = lcm_url;
    if (!sparkplug.empty()) {
      try {
        hoist::mqtt::applySparkplugOption(sparkplug, cfg);
      } catch (const std::invalid_argument& e) {
        std::cerr << "hoist-mqtt: " << e.what() << "\n";
        return 2;
      }
    }
    // systemd credentials (LoadCredential=, hoist-mqtt@.service): a non-empty
    // mqtt-password / mqtt-tls-key in $CREDENTIALS_DIRECTORY replaces
    // [broker] password_file / [tls] key_file, so those files can stay
    // root-only (mode 0600) while the bridge runs as a dynamic user.
    for (const auto& cred : hoist::mqtt::applyCredentials(cfg))
      spdlog::info("using the systemd credential {}", cred);
    try {
      cfg.validate();
    } catch (const std::invalid_argument& e) {
      std::cerr << "hoist-mqtt: " << e.what() << "\n";
      return 2;
    }
    password = hoist::mqtt::resolvePassword(cfg, config_path.empty() ? "<command line>" : config_path);
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-mqtt: " << e.what() << "\n";
    return 2;
  }
  // LCM URL precedence: --lcm-url, $LCM_DEFAULT_URL, [bridge] lcm_url, LCM's default.
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); lcm_url.empty() && env && *env) cfg.lcm_url = env;
  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-mqtt", app.count("--lcm-url") > 0, lcm_url, cfg.lcm_url); !bad.empty()) { std::cerr << bad << "\n"; return 2; }

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  mosquitto_lib_init();
  int rc = 0;
  try {
    hoist::mqtt::Bridge bridge(cfg, password);
    rc = bridge.run(g_stop);
  } catch (const hoist::mqtt::JournalError& e) {  // [buffer] dir unusable: a configuration error
    std::cerr << "hoist-mqtt: " << e.what() << "\n";
    rc = 2;
  } catch (const std::exception& e) {
    std::cerr << "hoist-mqtt: " << e.what() << "\n";
    rc = 1;
  }
  mosquitto_lib_cleanup();
  return rc;
}
