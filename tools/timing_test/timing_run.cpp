// hoist-replay --timing-test: the listener and the run (see timing_test.hpp);
// the feeder is timing_feeder.*.
//
// Threads: the feeder (own LCM instance, publish only, absolute schedule on
// CLOCK_MONOTONIC, signals blocked) and the main thread (the listener:
// HOIST_HEALTH and HOIST_CAGE of every prefix, progress, signals).  The
// listener receives udpm:// through hoist::bus::Subscriber's UdpmReceiver (exact channel
// names, nothing stored per name: a sender cycling through channel names
// cannot grow it, unlike LCM 1.3.1's receive path), with an 8 MiB socket
// buffer for the outputs of hundreds of shafts; other LCM providers through
// LCM's subscribe.
// They share only atomics: the per-shaft rings of publish times (indexed by
// seq) and the sent counters; the feeder's lateness histogram is read after
// the join.
#include <algorithm>
#include <pthread.h>
#include <signal.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <memory>
#include <thread>


#include "hoist/cage_state_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/profile.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/winder_t.hpp"
#include "timing_feeder.hpp"
#include "timing_test.hpp"

namespace hoist::replay {

namespace {

std::atomic<int> g_signal{0};
std::atomic<int> g_signal_count{0};
void onSignal(int sig) {
  g_signal.store(sig);
  g_signal_count.fetch_add(1);
}

/// Counters of one health report that are judged as deltas.
struct Counters {
  std::int64_t misses = 0, rejected = 0, accepted = 0, seq_gaps = 0, faults = 0, resets = 0, pubfail = 0,
               nonfinite = 0;
  std::map<std::string, std::int64_t> reasons;
  static Counters of(const hoist::health_t& h) {
    Counters c;
    c.misses = h.deadline_misses;
    c.rejected = h.rejected_total;
    c.accepted = h.accepted;
    c.seq_gaps = h.seq_gaps;
    c.faults = h.model_faults;
    c.resets = h.model_resets;
    c.pubfail = h.publish_failures;
    c.nonfinite = h.nonfinite_blocked;
    for (int i = 0; i < h.n_reasons && i < static_cast<int>(h.rejected.size()) &&
                    i < static_cast<int>(h.reject_reason.size());
         ++i)
      c.reasons[h.reject_reason[static_cast<std::size_t>(i)]] = h.rejected[static_cast<std::size_t>(i)];
    return c;
  }
  void addDelta(const Counters& last, const Counters& base) {
    misses += last.misses - base.misses;
    rejected += last.rejected - base.rejected;
    accepted += last.accepted - base.accepted;
    seq_gaps += last.seq_gaps - base.seq_gaps;
    faults += last.faults - base.faults;
    resets += last.resets - base.resets;
    pubfail += last.pubfail - base.pubfail;
    nonfinite += last.nonfinite - base.nonfinite;
    for (const auto& [k, v] : last.reasons) {
      auto it = base.reasons.find(k);
      reasons[k] += v - (it == base.reasons.end() ? 0 : it->second);
    }
  }
};

enum class Phase { Pre, Feeding, Post, Done };

struct Run;

struct Shaft {
  Run* run = nullptr;
  std::size_t idx = 0;
  ShaftResult res;
  const Ring* ring = nullptr;  // the feeder's publish times of this shaft
  bool have_base = false, have_last = false;
  Counters base, last, carry;  // carry: deltas before a daemon restart
  std::int64_t base_utime = 0, last_utime = 0;
  double prev_uptime = -1.0;
  std::int64_t answered = -1;  // highest input_seq answered so far
  void onHealth(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void onCage(const lcm::ReceiveBuffer* rb, const std::string& channel);
};

struct Run {
  const TimingTestOptions& o;
  Phase phase = Phase::Pre;
  std::int64_t feed_start_utime = 0;
  std::int64_t feed_end_utime = std::numeric_limits<std::int64_t>::max();
  const std::atomic<std::int64_t>* sent = nullptr;  // per shaft, from the feeder
  std::vector<std::unique_ptr<Shaft>> shafts;
  explicit Run(const TimingTestOptions& opt) : o(opt) {}
};

// LCM callbacks: bytes checked before decoding, and no exception escapes
// (function-try-blocks; a failure drops the message).
void Shaft::onHealth(const lcm::ReceiveBuffer* rb, const std::string& /*channel*/) try {
  hoist::health_t h;
  if (hoist::msg::checkedDecode(rb->data, rb->data_size, h) != hoist::msg::DecodeStatus::ok) return;
  const Run& r = *run;
  if (r.phase == Phase::Done || res.final_report) return;
  res.heard = true;
  res.clock = h.clock;
  res.daemon_rate = h.rate;
  if (h.window > 0.0 && std::isfinite(h.window)) res.health_interval_s = h.window;
  const bool restarted = prev_uptime >= 0.0 && h.uptime + 1e-3 < prev_uptime;
  prev_uptime = h.uptime;
  const Counters c = Counters::of(h);
  if (r.phase == Phase::Pre || !have_base) {
    base = c;
    base_utime = h.utime;
    have_base = true;
    return;
  }
  if (restarted) {
    // A new daemon counts from zero: keep what the old one counted.
    res.restarted = true;
    carry.addDelta(have_last ? last : base, base);
    base = Counters{};
    for (const auto& kv : c.reasons) base.reasons[kv.first] = 0;
  }
  ++res.windows;
  res.late_p99_worst = std::max(res.late_p99_worst, h.late_p99_us);
  res.late_max = std::max(res.late_max, h.late_max_us);
  res.step_p99_worst = std::max(res.step_p99_worst, h.step_p99_us);
  res.step_max = std::max(res.step_max, h.step_max_us);
  const std::int64_t grace = std::llround(2e6 / r.o.rate);
  if (h.degraded && h.utime > r.feed_start_utime + grace && h.utime <= r.feed_end_utime) ++res.degraded_health;
  last = c;
  last_utime = h.utime;
  have_last = true;
  // The first report after the last input (with a margin for its processing).
  if (r.phase == Phase::Post && h.utime >= r.feed_end_utime + 20000) res.final_report = true;
} catch (...) {
}

void Shaft::onCage(const lcm::ReceiveBuffer* rb, const std::string& /*channel*/) try {
  const Run& r = *run;
  if (r.phase != Phase::Feeding && r.phase != Phase::Post) return;
  hoist::cage_state_t c;
  if (hoist::msg::checkedDecode(rb->data, rb->data_size, c) != hoist::msg::DecodeStatus::ok) return;
  std::int64_t t_pub = 0;
  if (!ring->get(c.input_seq, t_pub)) {
    // Ours but already overwritten in the ring (a very late answer)?
    if (c.input_seq >= 0 && c.input_seq < r.sent[idx].load(std::memory_order_relaxed) && c.input_seq > answered) {
      ++res.e2e_unmatched;
      answered = c.input_seq;
    }
    return;
  }
  ++res.cage_msgs;
  if (c.degraded && rb->recv_utime <= r.feed_end_utime) ++res.degraded_cage;
  if (c.input_seq > answered) {
    answered = c.input_seq;
    res.e2e.add(static_cast<double>(rb->recv_utime - t_pub));
  }
} catch (...) {
}

std::string hostName() {
  utsname u{};
  if (uname(&u) != 0) return "?";
  return u.nodename;
}

std::string isoDateUtc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::size_t ringSize(double rate, std::size_t shafts) {
  // 8 s of inputs per shaft, at most ~4 M slots (64 MB) in all, at least 1 s.
  const double want = std::max(rate * std::clamp(4194304.0 / (rate * static_cast<double>(shafts)), 1.0, 8.0), 64.0);
  std::size_t n = 64;
  while (static_cast<double>(n) < want) n <<= 1;
  return n;
}

}  // namespace

int runTimingTest(const TimingTestOptions& o) {
  // Opened now, so a bad path fails before the run; every byte checked at
  // the end (hoist/io/checked_file.hpp).
  hoist::io::CheckedFile report;
  if (!o.report_path.empty()) {
    try {
      report = hoist::io::CheckedFile(o.report_path, "--report");
    } catch (const hoist::io::WriteError& e) {
      std::cerr << "hoist-timing-test: " << e.what() << "\n";
      return 2;
    }
  }
  auto say = [&](const std::string& s) {
    if (o.progress) std::cerr << "hoist-timing-test: " << s << "\n";
  };

  const std::string& rx_url = o.lcm_url_out.empty() ? o.lcm_url : o.lcm_url_out;
  // The listener's receive path for rx_url (ours for udpm://, else an LCM
  // instance of its own): hoist/bus/subscriber.hpp.
  hoist::bus::Subscriber rx;
  std::string rx_why;
  if (!rx.open(rx_url, rx_why, 8 << 20)) {
    std::cerr << "hoist-timing-test: " << rx_why << "\n";
    return 1;
  }
  lcm::LCM tx(o.lcm_url);
  if (!tx.good()) {
    std::cerr << "hoist-timing-test: cannot open LCM at " << hoist::bus::describeLcmUrl(o.lcm_url) << "\n";
    return 1;
  }
  // Wait up to `ms` for datagrams and dispatch what arrived.
  auto receive = [&](int ms) { rx.poll(ms, 4096); };
  const RoundTrip trip(o.l0, o.travel, o.vmax, o.amax);

  Run run(o);
  const std::size_t ring = ringSize(o.rate, o.prefixes.size());
  std::vector<Ring> rings;
  rings.reserve(o.prefixes.size());
  for (std::size_t i = 0; i < o.prefixes.size(); ++i) rings.emplace_back(ring);
  for (std::size_t i = 0; i < o.prefixes.size(); ++i) {
    auto s = std::make_unique<Shaft>();
    s->run = &run;
    s->ring = &rings[i];
    s->idx = i;
    s->res.prefix = o.prefixes[i];
    run.shafts.push_back(std::move(s));
  }
  for (auto& s : run.shafts) {
    const std::string health = hoist::bus::channel(s->res.prefix, hoist::bus::kChannelHealth);
    const std::string cage = hoist::bus::channel(s->res.prefix, hoist::bus::kChannelCage);
    Shaft* sh = s.get();
    rx.add(health, [sh](const lcm::ReceiveBuffer* rb, const std::string& c) { sh->onHealth(rb, c); });
    rx.add(cage, [sh](const lcm::ReceiveBuffer* rb, const std::string& c) { sh->onCage(rb, c); });
  }

  struct sigaction sa {};
  sa.sa_handler = onSignal;  // no SA_RESTART: interrupt the waits
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);

  TimingResult result;
  result.host = hostName();
  result.date = isoDateUtc();
  auto finish = [&](TimingResult& res) {
    const Evaluation e = evaluate(res, o);
    const std::string text = formatReport(res, o, e);
    std::cout << text << std::flush;
    bool report_failed = false;
    if (report.isOpen()) {
      try {
        report.write(text);
        report.close();
      } catch (const hoist::io::WriteError& e) {
        std::cerr << "hoist-timing-test: " << e.what() << "\n";
        report_failed = true;
      }
    }
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    if (res.interrupted) return 128 + res.signal;
    if (report_failed) return 1;
    return e.verdict == Verdict::Pass ? 0 : 1;
  };

  // 1. Every daemon must be there: its first HOIST_HEALTH is the baseline.
  say("timing test: waiting for HOIST_HEALTH on " + hoist::bus::channel(o.prefixes.front(), hoist::bus::kChannelHealth) +
      (o.prefixes.size() > 1 ? " and " + std::to_string(o.prefixes.size() - 1) + " more" : std::string()) +
      " (LCM " + hoist::bus::describeLcmUrl(o.lcm_url) + ")");
  auto allHeard = [&] {
    for (auto& s : run.shafts)
      if (!s->have_base) return false;
    return true;
  };
  {
    const std::int64_t end = monotonicNs() + std::llround(o.health_timeout * 1e9);
    while (!allHeard() && monotonicNs() < end && !g_signal.load()) receive(50);
  }
  if (g_signal.load()) {
    std::cerr << "hoist-timing-test: stopped before the timing test started\n";
    if (report.isOpen()) {
      try {
        report.write("VERDICT: INCONCLUSIVE (shortened run: stopped before the test started)\n");
        report.close();
      } catch (const hoist::io::WriteError& e) {
        std::cerr << "hoist-timing-test: " << e.what() << "\n";
      }
    }
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    return 128 + g_signal.load();
  }
  if (!allHeard()) {
    result.no_health = true;
    for (auto& s : run.shafts) {
      result.shafts.push_back(s->res);
      if (!s->have_base)
        std::cerr << "hoist-timing-test: no HOIST_HEALTH on " << s->res.prefix << "HOIST_HEALTH within " << o.health_timeout
                  << " s: is hoist-twind running with the same --lcm-url and channel prefix?\n";
    }
    return finish(result);
  }

  // 2. Feed, listening meanwhile.
  Feeder feeder(o, tx, trip, rings);
  run.sent = feeder.sent.get();
  {
    char line[160];
    std::snprintf(line, sizeof line, "timing test: feeding %zu shaft(s) at %g Hz for %g s", o.prefixes.size(),
                  o.rate, o.duration);
    say(line);
  }
  run.feed_start_utime = hoist::bus::wallUtime();
  run.phase = Phase::Feeding;
  std::thread th;
  {
    sigset_t block, prev;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &block, &prev);
    th = std::thread([&feeder] { feeder.run(); });
    pthread_sigmask(SIG_SETMASK, &prev, nullptr);
  }
  const std::int64_t t0 = monotonicNs();
  std::int64_t next_progress = t0 + 1'000'000'000;
  while (!feeder.done.load()) {
    receive(20);
    if (g_signal.load()) feeder.stop.store(true);
    if (o.progress && monotonicNs() >= next_progress) {
      next_progress += 1'000'000'000;
      std::int64_t sent = 0, misses = 0;
      double late = 0.0;
      for (std::size_t i = 0; i < run.shafts.size(); ++i) {
        const Shaft& s = *run.shafts[i];
        sent += feeder.sent[i].load(std::memory_order_relaxed);
        misses += s.carry.misses + (s.have_last ? s.last.misses - s.base.misses : 0);
        late = std::max(late, s.res.late_p99_worst);
      }
      std::fprintf(stderr, "hoist-timing-test: timing test %4.0f/%g s  sent %lld  misses %lld  worst late p99 %.1f us\n",
                   static_cast<double>(monotonicNs() - t0) * 1e-9, o.duration, static_cast<long long>(sent),
                   static_cast<long long>(misses), late);
    }
  }
  th.join();
  run.feed_end_utime = std::max(feeder.last_utime.load(), run.feed_start_utime);
  run.phase = Phase::Post;

  // 3. The first health report after the last input closes each shaft.
  double interval = 1.0;
  for (auto& s : run.shafts) interval = std::max(interval, s->res.health_interval_s);
  double wait_s = std::clamp(1.5 * interval + 0.5, 1.5, 12.0);
  if (g_signal.load()) wait_s = std::min(wait_s, 2.0);
  auto allFinal = [&] {
    for (auto& s : run.shafts)
      if (!s->res.final_report) return false;
    return true;
  };
  {
    const std::int64_t end = monotonicNs() + std::llround(wait_s * 1e9);
    while (!allFinal() && monotonicNs() < end && g_signal_count.load() < 2) receive(50);
  }
  run.phase = Phase::Done;

  result.elapsed = static_cast<double>(feeder.end_ns - feeder.start_ns) * 1e-9;
  result.interrupted = g_signal.load() != 0;
  result.signal = g_signal.load();
  result.feeder_late = feeder.late;
  result.feeder_skipped = feeder.skipped;
  for (std::size_t i = 0; i < run.shafts.size(); ++i) {
    Shaft& s = *run.shafts[i];
    ShaftResult r = s.res;
    r.sent = feeder.sent[i].load();
    r.publish_failed = feeder.failed[i];
    Counters d = s.carry;
    if (s.have_last) d.addDelta(s.last, s.base);
    r.misses = d.misses;
    r.rejected = d.rejected;
    r.accepted = d.accepted;
    r.seq_gaps = d.seq_gaps;
    r.model_faults = d.faults;
    r.model_resets = d.resets;
    r.publish_failures = d.pubfail;
    r.nonfinite_blocked = d.nonfinite;
    for (const auto& [k, v] : d.reasons)
      if (v != 0) r.rejected_by_reason[k] = v;
    if (!r.final_report)
      r.health_gap_s = static_cast<double>(run.feed_end_utime - (s.have_last ? s.last_utime : s.base_utime)) * 1e-6;
    result.shafts.push_back(std::move(r));
  }
  return finish(result);
}

}  // namespace hoist::replay
