// hoist-wakeup-latency: the machine's own timer wake-up latency, measured the
// way hoist-twind schedules its ticks (absolute deadlines every period), with
// no work at all -- a cyclictest-like baseline for bench/rt_report.sh.  If the
// bare machine misses deadlines, the daemon cannot do better.
//
//   hoist-wakeup-latency [--rate HZ] [--seconds S] [--rt-priority N] [--cpus LIST] [--mlockall]
//
// Prints one JSON object: ticks, deadline misses (wake-ups more than one
// period late), lateness p50/p99/p99.9/max [us] and the real-time settings
// obtained.
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hoist/version.hpp"

int main(int argc, char** argv) {
  double rate = 1000.0, seconds = 60.0;
  int prio = 0;
  bool mlock = false;
  std::string cpus;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "hoist-wakeup-latency: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--rate") rate = std::atof(next());
    else if (a == "--seconds") seconds = std::atof(next());
    else if (a == "--rt-priority") prio = std::atoi(next());
    else if (a == "--cpus") cpus = next();
    else if (a == "--mlockall") mlock = true;
    else if (a == "--version") {
      std::printf("hoist-wakeup-latency %s\n", hoist::kVersionString);
      return 0;
    }
    else if (a == "-h" || a == "--help") {
      std::puts(
          "Usage: hoist-wakeup-latency [OPTIONS]\n"
          "The machine's timer wake-up latency on an absolute schedule (cyclictest-like); JSON on stdout.\n"
          "The baseline of bench/rt_report.sh: what the daemon's loop cannot do better than.\n"
          "\n"
          "Options:\n"
          "  --rate HZ          wake-ups per second, 1..10000 (default 1000)\n"
          "  --seconds S        how long to measure [s], > 0 (default 60)\n"
          "  --rt-priority N    run SCHED_FIFO at this priority, 1..99 (default: SCHED_OTHER)\n"
          "  --cpus CPU         pin to these CPUs, e.g. 1 or 2-3 (default: not pinned)\n"
          "  --mlockall         lock all memory (mlockall)\n"
          "  --version          print the version and exit\n"
          "  -h, --help         this help\n"
          "\n"
          "Exit status: 0 measured, 2 bad usage.");
      return 0;
    } else {
      std::fprintf(stderr, "hoist-wakeup-latency: unknown option %s (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (!(rate >= 1.0 && rate <= 10000.0) || !(seconds > 0.0)) {
    std::fprintf(stderr, "hoist-wakeup-latency: --rate must be in [1, 10000] and --seconds > 0\n");
    return 2;
  }
  std::string mlock_s = "not requested", sched_s = "SCHED_OTHER", aff_s = "not set";
  if (mlock) mlock_s = mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? "on" : std::string("FAILED (") + std::strerror(errno) + ")";
  if (prio > 0) {
    sched_param sp{};
    sp.sched_priority = prio;
    const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    sched_s = e == 0 ? "SCHED_FIFO " + std::to_string(prio) : std::string("FAILED (") + std::strerror(e) + ")";
  }
  if (!cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(std::atoi(cpus.c_str()), &set);
    const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    aff_s = e == 0 ? "CPU " + cpus : std::string("FAILED (") + std::strerror(e) + ")";
  }
  const long period_ns = std::lround(1e9 / rate);
  const long n = std::lround(seconds * rate);
  std::vector<double> late;
  late.reserve(static_cast<std::size_t>(n));
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  const auto ns = [](const timespec& t) { return static_cast<long long>(t.tv_sec) * 1000000000LL + t.tv_nsec; };
  const long long t0 = ns(start);
  long long k = 1, misses = 0;
  while (static_cast<long>(late.size()) < n) {
    const long long due = t0 + k * period_ns;
    timespec ts{static_cast<time_t>(due / 1000000000LL), static_cast<long>(due % 1000000000LL)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const long long nn = ns(now);
    late.push_back(static_cast<double>(nn - due) / 1000.0);
    const long long passed = (nn - t0) / period_ns;  // the daemon's rule: skip missed periods
    if (passed > k) {
      misses += passed - k;
      k = passed;
    }
    ++k;
  }
  std::vector<double> s = late;
  std::sort(s.begin(), s.end());
  auto q = [&](double p) { return s[std::min(s.size() - 1, static_cast<std::size_t>(std::ceil(p * static_cast<double>(s.size()))) - (p > 0 ? 1 : 0))]; };
  nlohmann::ordered_json j;
  j["rate_hz"] = rate;
  j["seconds"] = seconds;
  j["ticks"] = s.size();
  j["deadline_misses"] = misses;
  const auto r1 = [](double x) { return std::round(x * 10.0) / 10.0; };
  j["late_us"] = {{"p50", r1(q(0.5))}, {"p99", r1(q(0.99))}, {"p999", r1(q(0.999))}, {"max", r1(s.back())}};
  j["over_period"] = std::count_if(s.begin(), s.end(), [&](double x) { return x > period_ns / 1000.0; });
  j["memory_lock"] = mlock_s;
  j["scheduling"] = sched_s;
  j["affinity"] = aff_s;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}
