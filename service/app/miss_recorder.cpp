// The miss recorder: see miss_recorder.hpp.
#include "miss_recorder.hpp"

#include <algorithm>
#include <ctime>

#include "hoist/bus/lcm_util.hpp"
#include "shaft_twin.hpp"

namespace hoist::service::inline app {

using std::chrono::duration;

MissRecorder::MissRecorder(boost::asio::io_context& io, rt::RtLog& log, const LoopSplit& split)
    : rtlog_(log), split_(split), ring_(std::make_unique<MissLog>()), timer_(io) {}

std::int64_t MissRecorder::threadCpuNanos() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

MissRecord& MissRecorder::begin(const MissTick& t, const MissWindow& w, Clock::time_point start,
                                Clock::time_point now, Clock::time_point deadline, std::int64_t skipped,
                                std::int64_t cpu_now) {
  MissRecord& r = ring_->begin();
  r.utime = bus::wallUtime();
  r.wall = duration<double>(now - start).count();
  r.model_t = static_cast<double>(t.tick) / t.rate;
  r.group = t.group;
  r.rate = t.rate;
  r.tick = t.tick;
  r.skipped = skipped;
  r.late_us = duration<double, std::micro>(now - deadline).count();
  r.shafts = t.shafts;
  const LoopSplit& a = w.split_at;
  const LoopSplit& b = split_;
  r.work = LoopSplit{b.receive - a.receive, b.step - a.step,     b.envelope - a.envelope, b.publish - a.publish,
                     b.forecast - a.forecast, b.start - a.start, b.health - a.health,     b.other - a.other};
  r.window_us = duration<double, std::micro>(now - w.last_start).count();
  const double work_us = 1e-3 * static_cast<double>(r.work.sum());
  // The loop works first (the previous tick, inputs) and then idles until
  // the deadline; what is left of the interval is the timer's: its wake-up,
  // the kernel, a stall of the machine.
  const double to_deadline_us = duration<double, std::micro>(deadline - w.last_start).count();
  r.idle_us = std::max(0.0, to_deadline_us - work_us);
  r.timer_us = std::max(0.0, r.window_us - work_us - r.idle_us);
  r.cpu_us = w.cpu_at > 0 && cpu_now > 0 ? 1e-3 * static_cast<double>(cpu_now - w.cpu_at) : -1.0;
  return r;
}

void MissRecorder::noteShaft(MissRecord& r, ShaftTwin& s, int id, double period_us) {
  const double late = s.lastLateUs();
  if (late > period_us) ++r.shafts_late;
  if (r.first_shaft < 0) {
    r.first_shaft = id;
    r.first_late_us = late;
  }
  if (r.worst_shaft < 0 || late > r.worst_late_us) {
    r.worst_shaft = id;
    r.worst_late_us = late;
  }
  s.noteMiss(r.seq, late);
}

void MissRecorder::startLogging() { arm(); }

void MissRecorder::stop() {
  stopped_ = true;
  timer_.cancel();
}

void MissRecorder::arm() {
  timer_.expires_after(std::chrono::seconds(1));
  timer_.async_wait([this](const boost::system::error_code& ec) { onSecond(ec); });
}

void MissRecorder::onSecond(const boost::system::error_code& ec) {
  if (ec || stopped_) return;
  const std::int64_t total = ring_->total();
  if (total > logged_) {
    // The worst of the new ones that the ring still keeps.
    const std::int64_t oldest = total - static_cast<std::int64_t>(ring_->kept());
    const MissRecord* w = nullptr;
    for (std::int64_t q = std::max(logged_, oldest); q < total; ++q) {
      const MissRecord& r = ring_->at(static_cast<std::size_t>(q - oldest));
      if (!w || r.late_us > w->late_us) w = &r;
    }
    if (w) {
      const LoopSplit& x = w->work;
      auto ms = [](std::int64_t ns) { return 1e-6 * static_cast<double>(ns); };
      rtlog_.warn("deadline misses: {} in the last second ({} since start); the worst: tick {} of the {} Hz "
                  "schedule (t = {:.2f} s) {:.2f} ms late, {} deadline(s) skipped, {} of {} shafts more than a "
                  "period late; since the previous tick [ms]: receive {:.2f}, step {:.2f}, envelope {:.2f}, "
                  "publish {:.2f}, forecast {:.2f}, start {:.2f}, health {:.2f}, other {:.2f}, timer {:.2f}, "
                  "idle {:.2f}; the loop thread's CPU time {:.2f}",
                  total - logged_, total, w->tick, w->rate, w->model_t, 1e-3 * w->late_us, w->skipped,
                  w->shafts_late, w->shafts, ms(x.receive), ms(x.step), ms(x.envelope), ms(x.publish),
                  ms(x.forecast), ms(x.start), ms(x.health), ms(x.other), 1e-3 * w->timer_us, 1e-3 * w->idle_us,
                  1e-3 * w->cpu_us);
    }
    logged_ = total;
  }
  arm();
}

}  // namespace hoist::service::app
