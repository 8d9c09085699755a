// hoist-replay -- publishes the winder input HOIST_WINDER (winder_t) for
// hoist-twind, in real time or faster.
//
//   hoist-replay [--profile FILE|SPEC | --lcm-log FILE | --measurements FILE.csv]
//                [--speed X] [--rate HZ]
//                [--lcm-url URL] [--with-length] [--channel-prefix P]
//
// Sources:
//   * a synthetic profile SPEC (hoist_io): `paper` (the default: the paper's
//     Fig. 2 trapezoid, 50 m -> 300 m in 60 s), `trapezoid:...`, `scurve:...`,
//     `estop:...`; or a profile CSV (t, v, a [, l]; docs/offline.md).  Sampled
//     at --rate (default 100 Hz) at t_k = t0 + k / rate, k = 0 .. round((t_end -
//     t0) * rate), exactly the times hoist-sim --dt 1/rate steps to;
//   * an LCM log (lcm-logger): every event whose channel ends in HOIST_WINDER
//     is re-published with its recorded timing, payload unchanged (so
//     `hoist-twind --clock input` reproduces the recorded run), unless
//     --restamp rewrites utime to the replay's wall clock.  The log is read
//     with hoist::io::LcmLogReader (validated headers, resynchronisation on
//     the next event after a corrupted one) and each payload must pass
//     hoist::msg::checkedDecode as a winder_t; skipped bytes, lost events and
//     undecodable payloads are reported and make the exit status 1 unless
//     --lenient.
//   * a measurement CSV (t,l,v,a[,f_y,omega,rope_load]; hoist-sim
//     --write-measurements, hoist-estimate's input): every row is published
//     at its own time -- first HOIST_CAGE_IMU (cage_imu_t, when the row has
//     both f_y and omega) and HOIST_ROPE_LOAD (rope_load_t, when it has
//     rope_load), then HOIST_WINDER with the row's l (has_length), v and a,
//     all with the row's utime -- so that the daemon has a step's sensor
//     samples when the step's winder input arrives.  Each channel has its
//     own seq = 0, 1, 2, ...; --rate does not apply.
//     --lenient.  A gap between consecutive HOIST_WINDER timestamps longer
//     than --max-gap S (default 10 s; a corrupted log had gaps of 33 s, 67 s
//     and 10^15 us), or a timestamp that goes backwards, is reported on
//     stderr and played as S seconds (backwards: as no pause), so a replay
//     never sleeps for hours without a word; --restamp utimes follow the
//     shortened timeline.
// Message k carries seq = k and utime = (wall time at start, us) + round((t_k -
// t0) * 1e6): utime follows PROFILE time whatever the speed, so that
// `hoist-twind --clock input` steps the model exactly by the profile's dt.
// --speed X publishes X times faster than real time (0 = as fast as possible;
// over UDP a too fast stream may overrun the receiver's socket buffer, which
// the daemon counts as sequence gaps).  Sleeps follow an absolute schedule
// (clock_nanosleep TIMER_ABSTIME), so timing errors do not accumulate.
// Progress is shown on a terminal only.  Ctrl-C stops cleanly (status 130).
//
// --timing-test: an alias of hoist-timing-test (timing_cli.hpp), the
// soft-real-time check of a running hoist-twind.
#include "hoist/cli/app.hpp"
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "hoist/io/lcm_log.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/daemon_shaft.hpp"
#include "cli_util.hpp"
#include "timing_cli.hpp"

namespace {

using hoist::replay::numberIn;

volatile std::sig_atomic_t g_signal = 0;
void onSignal(int sig) { g_signal = sig; }

/// Sleep until the absolute CLOCK_MONOTONIC time `deadline_ns`; false if a
/// signal asked us to stop.
bool sleepUntil(std::int64_t deadline_ns) {
  timespec ts{static_cast<time_t>(deadline_ns / 1000000000), static_cast<long>(deadline_ns % 1000000000)};
  while (!g_signal) {
    const int r = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    if (r == 0) return true;
    if (r != EINTR) return true;
  }
  return false;
}

std::int64_t monotonicNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

class Progress {
 public:
  explicit Progress(bool on) : on_(on) {}
  void update(double t, double t0, double t1, long sent) {
    if (!on_) return;
    const std::int64_t now = monotonicNs();
    if (now - last_ < 200000000) return;
    last_ = now;
    const double f = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
    std::fprintf(stderr, "\rhoist-replay: t = %8.2f / %.2f s  %5.1f %%  %ld messages ", t, t1, 100.0 * f, sent);
    std::fflush(stderr);
  }
  void done() {
    if (on_) std::fputc('\n', stderr);
  }
  bool active() const { return on_ && last_ != 0; }

 private:
  bool on_;
  std::int64_t last_ = 0;
};

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  // --timing-test: the same as hoist-timing-test (kept as an alias).
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--timing-test") continue;
    std::vector<char*> rest(argv, argv + argc);
    rest.erase(rest.begin() + i);
    return hoist::replay::timingTestMain(static_cast<int>(rest.size()), rest.data(), "hoist-replay --timing-test");
  }
  for (int i = 1; i < argc; ++i)
    for (const auto& o : hoist::replay::timingOnlyOptions())
      if (std::string(argv[i]) == o || std::string(argv[i]).rfind(o + "=", 0) == 0) {
        std::cerr << "hoist-replay: " << o << " requires --timing-test (or use hoist-timing-test)\n";
        return 2;
      }
  CLI::App app{
      "hoist-replay: publish the winder input (LCM channel HOIST_WINDER) for hoist-twind from\n"
      "a synthetic hoist profile, a profile CSV or an LCM log, in real time or at --speed X.\n"
      "With no source it plays the paper's trapezoid (Fig. 2: 50 m -> 300 m, 60 s).\n"
      "--timing-test ... runs hoist-timing-test (the real-time check of a running hoist-twind)."};
  hoist::cli::nameProgram(app, "hoist-replay");
  std::string profile_arg, log_path, url, config_path;
  std::vector<std::string> prefixes;
  double speed = 1.0, rate = 100.0;
  bool with_length = false, restamp = false, quiet = false;
  auto* prof = app.add_option("--profile", profile_arg,
                              "profile CSV file, or SPEC: paper | trapezoid:... | scurve:... | estop:... "
                              "(see hoist-sim --help)");
  auto* logopt = app.add_option("--lcm-log", log_path, "re-publish HOIST_WINDER events of this LCM log")
                     ->check(CLI::ExistingFile);
  prof->excludes(logopt);
  logopt->excludes(prof);
  std::string meas_path;
  auto* measopt = app.add_option("--measurements", meas_path,
                                 "publish the winder and sensor channels (HOIST_WINDER with l, HOIST_CAGE_IMU, "
                                 "HOIST_ROPE_LOAD) from a measurement CSV t,l,v,a[,f_y,omega,rope_load] at its own "
                                 "times (hoist-sim --write-measurements writes one)")
                      ->check(CLI::ExistingFile);
  measopt->excludes(prof)->excludes(logopt);
  prof->excludes(measopt);
  logopt->excludes(measopt);
  app.add_option("--speed", speed, "playback speed factor; 0 = as fast as possible (default 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--rate", rate, "messages per second of profile time (default 100)")
      ->check(numberIn(0.1, 10000.0, false, "in [0.1, 10000] Hz"));
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  app.add_option("--channel-prefix", prefixes, "prepended to the channel name HOIST_WINDER")
      ->allow_extra_args(false);
  app.add_option("--config", config_path,
                 "shaft TOML: hoisting_rope.initial_length starts profiles that have no l column")
      ->check(CLI::ExistingFile);
  app.add_flag("--with-length", with_length, "include the encoder rope length l in every message");
  app.add_flag("--restamp", restamp, "--lcm-log: rewrite utime to the replay's wall clock");
  bool lenient = false;
  app.add_flag("--lenient", lenient,
               "--lcm-log: exit 0 even when corrupt events were skipped or payloads failed to decode");
  double max_gap = 10.0;
  app.add_option("--max-gap", max_gap,
                 "--lcm-log: a timestamp gap longer than S seconds between HOIST_WINDER events is reported and "
                 "played as S seconds (default 10)")
      ->check(numberIn(0.0, 1e6, false, "in [0, 1e6] s"));
  app.add_flag("-q,--quiet", quiet, "no progress display");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;

  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-replay", app.count("--lcm-url") > 0, url,
                                                            hoist::bus::resolveLcmUrl(url));
      !bad.empty()) {
    std::cerr << bad << "\n";
    return 2;
  }
  url = hoist::bus::resolveLcmUrl(url);
  if (prefixes.size() > 1) {
    std::cerr << "hoist-replay: --channel-prefix: only one prefix (several shafts: hoist-timing-test)\n";
    return 2;
  }
  const std::string prefix = prefixes.empty() ? std::string() : prefixes.front();
  // --measurements: read (and validate) the whole file before anything is published.
  std::vector<hoist::MeasurementSample> meas;
  if (!meas_path.empty()) {
    try {
      meas = hoist::io::readMeasurementsCsvFile(meas_path);
    } catch (const std::exception& e) {
      std::cerr << "hoist-replay: " << e.what() << "\n";
      return 2;
    }
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "hoist-replay: cannot open LCM at " << hoist::bus::describeLcmUrl(url) << "\n";
    return 1;
  }
  const std::string channel = hoist::bus::channel(prefix, hoist::bus::kChannelWinder);
  struct sigaction sa {};
  sa.sa_handler = onSignal;  // no SA_RESTART: interrupt the sleep
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  Progress progress(!quiet && isatty(STDERR_FILENO));
  const std::int64_t start_ns = monotonicNs();
  const std::int64_t start_utime = hoist::bus::wallUtime();
  long sent = 0, failed = 0;
  std::vector<std::uint8_t> buf(256);
  hoist::winder_t msg{};

  long log_bad = 0;
  bool log_lost = false;
  if (!log_path.empty()) {
    hoist::io::LcmLogReader log(log_path);
    if (!log.ok()) {
      std::cerr << "hoist-replay: " << log.error() << "\n";
      return 1;
    }
    std::int64_t first_ts = 0, first_utime = 0, prev_ts = 0, cut_us = 0;  // cut_us: time removed from gaps
    long gaps = 0;
    const std::int64_t max_gap_us = static_cast<std::int64_t>(std::llround(max_gap * 1e6));
    bool first = true;
    hoist::io::LcmLogEvent ev;
    while (log.next(ev)) {
      if (g_signal) break;
      if (!endsWith(ev.channel, std::string(hoist::bus::kChannelWinder))) continue;
      // Validate before anything is sent: the daemon would reject it anyway.
      if (const auto st = hoist::msg::checkedDecode(ev.data.data(), ev.data.size(), msg);
          st != hoist::msg::DecodeStatus::ok) {
        if (log_bad++ < 5)
          std::cerr << "hoist-replay: " << log_path << ": event " << ev.eventnum << " at byte " << ev.offset
                    << " on " << hoist::msg::terminalSafe(ev.channel) << " is not a valid hoist.winder_t ("
                    << hoist::msg::toString(st) << "); skipped\n";
        continue;
      }
      if (first) {
        first_ts = prev_ts = ev.timestamp;
        first = false;
      }
      // The gap in unsigned arithmetic: timestamps are whatever the file says.
      const auto gap = static_cast<std::int64_t>(static_cast<std::uint64_t>(ev.timestamp) -
                                                 static_cast<std::uint64_t>(prev_ts));
      if (gap > max_gap_us || gap < 0) {
        const std::int64_t played = gap < 0 ? 0 : max_gap_us;
        if (gaps++ < 10)
          std::fprintf(stderr, "%shoist-replay: %s: event %lld at byte %lld: timestamp %s %.6g s%s; played as %.6g s "
                               "(--max-gap %g)\n",
                       progress.active() ? "\n" : "", log_path.c_str(), static_cast<long long>(ev.eventnum),
                       static_cast<long long>(ev.offset), gap < 0 ? "goes back by" : "gap of",
                       std::fabs(static_cast<double>(gap)) * 1e-6, gap < 0 ? "" : " after the previous event",
                       static_cast<double>(played) * 1e-6, max_gap);
        cut_us = static_cast<std::int64_t>(static_cast<std::uint64_t>(cut_us) +
                                           static_cast<std::uint64_t>(gap - played));
      }
      prev_ts = ev.timestamp;
      const std::int64_t rel_us = static_cast<std::int64_t>(static_cast<std::uint64_t>(ev.timestamp) -
                                                            static_cast<std::uint64_t>(first_ts) -
                                                            static_cast<std::uint64_t>(cut_us));
      const double t_rel = static_cast<double>(rel_us) * 1e-6;
      if (speed > 0.0 && !sleepUntil(start_ns + static_cast<std::int64_t>(t_rel / speed * 1e9))) break;
      const void* data = ev.data.data();
      int len = static_cast<int>(ev.data.size());
      if (restamp) {
        if (sent == 0) first_utime = msg.utime;
        msg.utime = start_utime + (msg.utime - first_utime) - cut_us;
        len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
        data = buf.data();
      }
      if (lcm.publish(channel, data, static_cast<unsigned>(len)) != 0) ++failed;
      else ++sent;
      progress.update(t_rel, 0.0, t_rel, sent);
    }
    if (!log.ok()) {
      progress.done();
      std::cerr << "hoist-replay: error: " << log.error() << "\n";
      return 1;
    }
    log_lost = log.stats().lost() || log_bad > 0;
    if (!g_signal && (log_lost || gaps || !quiet))
      std::cerr << "hoist-replay: " << log_path << ": " << log.summary()
                << (log_bad ? "; " + std::to_string(log_bad) + " undecodable HOIST_WINDER payload(s) skipped"
                            : std::string())
                << (gaps ? "; " + std::to_string(gaps) + " timestamp gap(s) over --max-gap shortened" : std::string())
                << "\n";
  } else if (!meas_path.empty()) {
    const std::string ch_imu = hoist::bus::channel(prefix, hoist::bus::kChannelCageImu);
    const std::string ch_rope = hoist::bus::channel(prefix, hoist::bus::kChannelRopeLoad);
    const double t0 = meas.front().t, t1 = meas.back().t;
    long sent_imu = 0, sent_rope = 0, half_imu = 0;
    hoist::cage_imu_t imu{};
    hoist::rope_load_t rope{};
    auto publish = [&](const std::string& ch, const auto& m, long& count) {
      const int len = m.encode(buf.data(), 0, static_cast<int>(buf.size()));
      if (len < 0 || lcm.publish(ch, buf.data(), static_cast<unsigned>(len)) != 0) ++failed;
      else ++count;
    };
    const unsigned kImu = hoist::kSensorImuAccel | hoist::kSensorImuRate;
    for (std::size_t k = 0; k < meas.size() && !g_signal; ++k) {
      const hoist::MeasurementSample& m = meas[k];
      if (speed > 0.0 && !sleepUntil(start_ns + static_cast<std::int64_t>((m.t - t0) / speed * 1e9))) break;
      const std::int64_t utime = start_utime + std::llround((m.t - t0) * 1e6);
      if ((m.present & kImu) == kImu) {
        imu.utime = utime;
        imu.seq = sent_imu;
        imu.f_y = m.z.f_y;
        imu.omega = m.z.omega;
        publish(ch_imu, imu, sent_imu);
      } else if (m.present & kImu) {
        ++half_imu;  // cage_imu_t carries both or neither
      }
      if (m.present & hoist::kSensorRopeLoad) {
        rope.utime = utime;
        rope.seq = sent_rope;
        rope.force = m.z.rope_load;
        publish(ch_rope, rope, sent_rope);
      }
      msg.utime = utime;
      msg.seq = static_cast<std::int64_t>(k);
      msg.v = m.k.v;
      msg.a = m.k.a;
      msg.has_length = true;
      msg.length = m.k.l;
      publish(channel, msg, sent);
      progress.update(m.t, t0, t1, sent + sent_imu + sent_rope);
    }
    if (half_imu > 0)
      std::cerr << "hoist-replay: warning: " << half_imu << " row(s) of " << meas_path
                << " have only one of f_y and omega: no cage_imu_t sent for them (it carries both)\n";
    if (!quiet && !g_signal)
      std::cerr << "hoist-replay: published " << sent_imu << " messages on " << ch_imu << ", " << sent_rope
                << " on " << ch_rope << "\n";
  } else {
    double l0 = 50.0;
    try {
      if (!config_path.empty()) {
        // hoist-twind's whole file is accepted; only the shaft's l0 is used here.
        std::string note;
        l0 = hoist::io::loadDaemonShaft(config_path, "hoist-replay", &note).l0;
        if (!note.empty() && !quiet) std::cerr << note << "\n";
      }
    } catch (const std::exception& e) {
      std::cerr << "hoist-replay: " << e.what() << "\n";
      return 2;
    }
    hoist::HoistProfile profile;
    try {
      profile = hoist::io::loadProfile(profile_arg.empty() ? std::string("paper") : profile_arg, l0);
    } catch (const std::exception& e) {
      std::cerr << "hoist-replay: " << e.what() << "\n";
      return 2;
    }
    const double t0 = profile.startTime(), t1 = profile.endTime();
    const double dt = 1.0 / rate;
    const long steps = std::lround((t1 - t0) / dt);
    for (long k = 0; k <= steps && !g_signal; ++k) {
      const double t = t0 + static_cast<double>(k) * dt;
      if (speed > 0.0 && !sleepUntil(start_ns + static_cast<std::int64_t>((t - t0) / speed * 1e9))) break;
      const hoist::Kinematics kin = profile.at(t);
      msg.utime = start_utime + std::llround((t - t0) * 1e6);
      msg.seq = k;
      msg.v = kin.v;
      msg.a = kin.a;
      msg.has_length = with_length;
      msg.length = with_length ? kin.l : 0.0;
      const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
      if (len < 0 || lcm.publish(channel, buf.data(), static_cast<unsigned>(len)) != 0) ++failed;
      else ++sent;
      progress.update(t, t0, t1, sent);
    }
  }
  progress.done();
  if (g_signal) {
    std::cerr << "hoist-replay: stopped by signal after " << sent << " messages\n";
    return 128 + g_signal;
  }
  if (!quiet)
    std::cerr << "hoist-replay: published " << sent << " messages on " << channel
              << (failed ? " (" + std::to_string(failed) + " failed)" : std::string()) << "\n";
  if (log_lost) {
    std::cerr << "hoist-replay: " << (lenient ? "warning" : "error") << ": data lost in " << log_path
              << (lenient ? " -- ignored (--lenient)" : "; use --lenient to accept") << "\n";
    if (!lenient) return 1;
  }
  return failed ? 1 : 0;
}
