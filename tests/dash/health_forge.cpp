// Test helper (tests/dash, not installed): forged health_t datagrams, for the
// dashboard's discovery-poisoning test (dash_discovery).
//
//   hoist-test-health-forge LCM_URL PATTERN COUNT ROUNDS PERIOD_MS INSTANCE_ID
//
// Publishes one health_t on <name>HOIST_HEALTH for each of COUNT prefixes
// (PATTERN with "%d" replaced by 0..COUNT-1, or PATTERN itself when it has no
// "%d"), ROUNDS times, PERIOD_MS apart; instance_id = INSTANCE_ID (0: none).
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "hoist/health_t.hpp"

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: hoist-test-health-forge LCM_URL PATTERN COUNT ROUNDS PERIOD_MS INSTANCE_ID\n");
    return 2;
  }
  ::lcm::LCM lcm(argv[1]);
  if (!lcm.good()) {
    std::fprintf(stderr, "hoist-test-health-forge: cannot open LCM at %s\n", argv[1]);
    return 1;
  }
  const std::string pattern = argv[2];
  const int count = std::atoi(argv[3]), rounds = std::atoi(argv[4]), period_ms = std::atoi(argv[5]);
  const long long instance = std::atoll(argv[6]);
  for (int r = 0; r < rounds; ++r) {
    for (int i = 0; i < count; ++i) {
      std::string name = pattern;
      if (const auto at = name.find("%d"); at != std::string::npos) name.replace(at, 2, std::to_string(i));
      hoist::health_t h{};
      h.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch()).count();
      h.instance_id = instance;
      h.uptime = r;
      h.clock = "wall";
      h.rate = 100.0;
      h.window = 1.0;
      h.input_age = -1.0;
      h.rss_kb = -1;
      lcm.publish(name + "HOIST_HEALTH", &h);
      if (count > 1) std::this_thread::sleep_for(std::chrono::microseconds(300));  // no receive-buffer overflow
    }
    if (r + 1 < rounds) std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
  }
  return 0;
}
