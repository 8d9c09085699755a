// hoist-timing-test's feeder: see timing_feeder.hpp.
#include "timing_feeder.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>

#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::replay {

std::int64_t monotonicNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

RoundTrip::RoundTrip(double l0, double travel, double vmax, double amax) {
  const double D = std::fabs(travel);
  trip_ = D >= vmax * vmax / amax ? D / vmax + vmax / amax : 2.0 * std::sqrt(D / amax);
  const auto n = static_cast<long>(std::ceil(trip_ / 0.01));
  const double dt = trip_ / static_cast<double>(n);
  const HoistProfile there = HoistProfile::trapezoid(l0, vmax, amax, travel, trip_, dt);
  const HoistProfile back = HoistProfile::trapezoid(there.samples().back().k.l, vmax, amax, -travel, trip_, dt);
  std::vector<ProfileSample> s = there.samples();
  s.pop_back();  // the turn: the return trip's first sample (its acceleration)
  for (const auto& b : back.samples()) s.push_back({b.t + trip_, b.k});
  s.back() = ProfileSample{2.0 * trip_, there.samples().front().k};
  profile_ = HoistProfile(std::move(s));
}

bool Feeder::sleepUntil(std::int64_t deadline) {
  for (;;) {
    if (stop.load(std::memory_order_relaxed)) return false;
    const std::int64_t now = monotonicNs();
    if (now >= deadline) return true;
    const std::int64_t until = std::min(deadline, now + 100'000'000);
    timespec ts{static_cast<time_t>(until / 1000000000), static_cast<long>(until % 1000000000)};
    const int r = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    if (r != 0 && r != EINTR) return !stop.load();
  }
}

void Feeder::run() {
  const std::int64_t n = std::max<std::int64_t>(1, std::llround(o.duration * o.rate));
  const double period_ns = 1e9 / o.rate;
  std::vector<std::uint8_t> buf(256);
  std::vector<std::int64_t> seq(channels.size(), 0);
  hoist::winder_t msg{};
  msg.has_length = true;
  start_ns = monotonicNs();
  std::int64_t k = 0;
  while (k < n) {
    const std::int64_t deadline = start_ns + std::llround(static_cast<double>(k) * period_ns);
    if (!sleepUntil(deadline)) break;
    const std::int64_t now = monotonicNs();
    late.add(static_cast<double>(now - deadline) * 1e-3);
    // More than a period late: skip the periods that passed (the schedule
    // stays absolute; seq stays contiguous).
    const auto passed = static_cast<std::int64_t>(static_cast<double>(now - start_ns) / period_ns);
    if (passed > k) {
      skipped += std::min(passed, n) - k;
      k = passed;
      if (k >= n) break;
    }
    const Kinematics kin = trip.at(static_cast<double>(k) / o.rate);
    msg.v = kin.v;
    msg.a = kin.a;
    msg.length = kin.l;
    for (std::size_t i = 0; i < channels.size(); ++i) {
      const std::int64_t utime = hoist::bus::wallUtime();
      msg.utime = utime;
      msg.seq = seq[i];
      const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
      // Recorded before publishing: the answer may come back at once.
      rings[i].put(seq[i], utime);
      if (len < 0 || lcm.publish(channels[i], buf.data(), static_cast<unsigned>(len)) != 0) {
        ++failed[i];
        continue;
      }
      ++seq[i];
      sent[i].store(seq[i], std::memory_order_relaxed);
      last_utime.store(utime, std::memory_order_relaxed);
    }
    ++k;
  }
  if (k >= n) sleepUntil(start_ns + std::llround(static_cast<double>(n) * period_ns));
  end_ns = monotonicNs();
  done.store(true);
}

}  // namespace hoist::replay
