// hoist-twind's event loop: see daemon.hpp.
#include "daemon.hpp"

#include <algorithm>
#include <csignal>
#include <limits>
#include <map>
#include <systemd/sd-daemon.h>
#include <thread>
#include <random>
#include <unistd.h>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/rt/clock.hpp"
#include "run_report.hpp"
#include "hoist/version.hpp"

namespace hoist::service::inline app {

namespace asio = boost::asio;
using std::chrono::duration;
using std::chrono::duration_cast;

using rt::nanos;
using rt::processCpuNanos;

Daemon::Daemon(DaemonOptions opt, std::shared_ptr<spdlog::logger> log)
    : opt_(std::move(opt)),
      out_(std::move(log)),
      log_(out_, 4096),
      lcm_(opt_.lcm_url),
      lcm_fd_(io_),
      signals_(io_) {
  if (opt_.shafts.empty()) throw std::invalid_argument("no shaft configured");
  for (int sig : {SIGINT, SIGTERM, SIGQUIT, SIGHUP, SIGUSR1, SIGUSR2}) signals_.add(sig);
  {
    std::random_device rd;
    instance_id_ = static_cast<std::int64_t>(((static_cast<std::uint64_t>(rd()) << 32) ^ rd()) >> 1);
    if (instance_id_ == 0) instance_id_ = 1;
  }
  if (!opt_.lcm_url_out.empty() && opt_.lcm_url_out != opt_.lcm_url)
    lcm_out_ = std::make_unique<::lcm::LCM>(opt_.lcm_url_out);
  opt_.labels.resize(opt_.shafts.size());
  // One ShaftTwin per configuration, one schedule (timer) per distinct rate.
  std::map<double, RateGroup*> by_rate;
  for (std::size_t i = 0; i < opt_.shafts.size(); ++i) {
    TestHooks hooks = opt_.hooks;
    if (i > 0) hooks.slow_tick_at = -1.0;  // the slow tick is the first shaft's only
    shafts_.push_back(std::make_unique<ShaftTwin>(opt_.shafts[i], opt_.labels[i], lcm_, log_, hooks,
                                                  instance_id_, lcm_out_.get()));
    if (!opt_.state_dir.empty() && opt_.shafts[i].estimator.enabled)
      shafts_.back()->keepAccelOffset(opt_.state_dir + "/" + stateFileName("accel_offset", opt_.labels[i]), out_);
    if (i < opt_.history.size() && opt_.history[i].enabled) shafts_.back()->enableTrips(opt_.history[i]);
    // Shaft i publishes its shapes at phase i of the shape divider.
    shafts_.back()->attachLoop(&split_, &misses_.log(), static_cast<int>(i));
    const double rate = opt_.shafts[i].service.rate;
    const int budget = opt_.shafts[i].service.max_starts_per_tick;
    const int env_budget = opt_.shafts[i].service.max_exact_envelopes_per_tick;
    RateGroup*& g = by_rate[rate];
    if (!g) {
      groups_.push_back(std::make_unique<RateGroup>());
      g = groups_.back().get();
      g->rate = rate;
      g->period = duration_cast<Clock::duration>(duration<double>(1.0 / rate));
      g->timer = std::make_unique<asio::steady_timer>(io_);
      g->index = static_cast<int>(groups_.size() - 1);
      g->start_budget = budget > 0 ? budget : std::numeric_limits<int>::max();
      g->envelope_budget = env_budget > 0 ? env_budget : std::numeric_limits<int>::max();
    } else {
      if (budget > 0) g->start_budget = std::min(g->start_budget, budget);
      if (env_budget > 0) g->envelope_budget = std::min(g->envelope_budget, env_budget);
    }
    g->shafts.push_back(shafts_.back().get());
    g->ids.push_back(static_cast<int>(i));
  }
  for (auto& g : groups_) g->shafts.shrink_to_fit();
  std::vector<ShaftTwin*> all;
  for (auto& sp : shafts_) all.push_back(sp.get());
  keepers_ = std::make_unique<KeeperWorker>(all, opt_.state_dir, out_);  // operators' preload adoptions
  // The trip rooms: one pool of at most one worker per CPU for every shaft
  // with [history] enabled (trip_pool.hpp).
  std::size_t with_history = 0;
  for (auto& sp : shafts_) with_history += sp->trips() ? 1 : 0;
  if (with_history > 0) {
    const int cpus = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    trip_pool_ = std::make_unique<TripPool>(std::min(cpus, static_cast<int>(with_history)));
    for (auto& sp : shafts_) sp->setTripPool(trip_pool_.get());
  }
  // Look-ahead forecasts: one pool for the process; the forecasting shafts
  // are staggered over the forecast period (shaft i of N at phase i / N).
  std::vector<ShaftTwin*> fshafts;
  int workers = 0;
  for (auto& sp : shafts_)
    if (sp->forecastJob()) {
      fshafts.push_back(sp.get());
      workers = std::max(workers, sp->config().forecast.workers);
    }
  if (!fshafts.empty()) pool_ = std::make_unique<ForecastPool>(workers);
  for (std::size_t i = 0; i < fshafts.size(); ++i) {
    ShaftTwin* s = fshafts[i];
    const double phase = static_cast<double>(i) / static_cast<double>(fshafts.size());
    if (s->config().service.clock == ClockMode::Wall) {
      pool_->add(s->forecastJob());
      s->setForecastPool(pool_.get(), phase);
    } else {
      s->setForecastPool(nullptr, phase);  // --clock input: synchronous, deterministic
    }
  }
}

Daemon::~Daemon() {
  watchdog_.stop();
  if (keepers_) keepers_->stop();
  if (pool_) pool_->stop();
  if (trip_pool_) trip_pool_->stop();
  // The descriptor belongs to LCM: never let Asio close it.
  if (lcm_fd_.is_open()) lcm_fd_.release();
  log_.stop();
}

bool Daemon::start() {
  if (!checkLcm()) return false;
  applyRealtimeSettings();
  if (!openInput()) return false;
  openOutput();
  armLcm();
  if (lcm_out_) out_watch_.open(opt_.lcm_url_out, shafts_);  // a second publisher of our outputs there
  startForecasts();
  startTrips();
  // The watchdog thread starts while SIGINT/SIGTERM are still blocked, so it
  // never receives them.
  watchdog_.start();
  unblockStopSignals();
  armSignals();
  startSchedules();
  logStarted();
  started_ = true;
  return true;
}

bool Daemon::checkLcm() {
  if (!lcm_.good()) {
    out_->error("cannot open LCM at {}; for multicast on one machine see docs/service.md "
                "(ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo)",
                bus::describeLcmUrl(opt_.lcm_url));
    return false;
  }
  if (lcm_out_ && !lcm_out_->good()) {
    out_->error("cannot open the LCM output URL {} ([service] lcm_url_out)", bus::describeLcmUrl(opt_.lcm_url_out));
    return false;
  }
  return true;
}

void Daemon::applyRealtimeSettings() {
  rt_ = applyRealtime(opt_.realtime);
  (rt_.all_granted ? out_->info("real-time settings: {}", rt_.summary())
                   : out_->warn("real-time settings: {} (running without them)", rt_.summary()));
}

bool Daemon::openInput() {
  // The receive path for the URL (hoist/bus/subscriber.hpp): for udpm:// (and
  // LCM's default) our own, which dispatches only the subscribed channels by
  // exact name and stores nothing per channel name seen (LCM 1.3.1 would);
  // other providers go through LCM.  Without recv_buf_size in the URL the
  // udpm buffer holds 200 ms of every shaft's inputs (about 2 KiB of kernel
  // memory per datagram on loopback), at least 1 MiB and at most 64 MiB.
  double inputs_per_s = 0.0;
  for (const auto& s : shafts_) inputs_per_s += s->config().service.rate;
  const double want = std::clamp(0.2 * inputs_per_s * 2048.0, 1048576.0, 67108864.0);
  std::string why;
  if (!input_.open(opt_.lcm_url, why, static_cast<int>(want))) {
    out_->error("{}", why);
    return false;
  }
  for (auto& s : shafts_) s->subscribe(&input_);
  lcm_fd_.assign(input_.fd());
  if (const UdpmReceiver* rx = input_.udpm()) {
    for (auto& s : shafts_) s->setIgnoredCounter(&ignored_);
    UdpmUrl udpm;
    parseUdpmUrl(opt_.lcm_url, udpm, why);
    out_->info("input socket: receive buffer {} KiB granted ({} KiB asked{})", rx->rcvbuf() / 1024,
               (udpm.recv_buf_size > 0 ? udpm.recv_buf_size : static_cast<int>(want)) / 1024,
               udpm.recv_buf_size > 0 ? ", recv_buf_size of the URL" : "");
  }
  return true;
}

void Daemon::openOutput() {
  // Our own publisher for udpm URLs (one sendmmsg per batch of the tick's
  // cage/shape messages instead of one sendmsg each); else LCM's.
  const std::string& out_url = lcm_out_ ? opt_.lcm_url_out : opt_.lcm_url;
  UdpmUrl u;
  std::string why_out;
  if (!parseUdpmUrl(out_url, u, why_out)) return;
  sender_ = std::make_unique<UdpmSender>();
  if (sender_->open(u, why_out)) {
    for (auto& s : shafts_) s->setSender(sender_.get());
  } else {
    out_->warn("own output socket for {} failed ({}); publishing through LCM", bus::describeLcmUrl(out_url), why_out);
    sender_.reset();
  }
}

void Daemon::startForecasts() {
  if (!pool_ || pool_->empty()) return;
  pool_->start();
  out_->info("look-ahead forecasts: {} shaft(s) on one pool of {} worker thread(s) (SCHED_OTHER, nice {}: they "
             "give way to the loop)",
             pool_->jobs(), pool_->workers(), ForecastPool::kWorkerNice);
}

void Daemon::startTrips() {
  keepers_->start();
  if (!trip_pool_) return;
  trip_pool_->start();
  out_->info("trip history: {} shaft(s) on one pool of {} worker thread(s) (SCHED_OTHER, nice {}: they give way "
             "to the loop)",
             trip_pool_->rooms(), trip_pool_->workers(), TripPool::kWorkerNice);
}

void Daemon::unblockStopSignals() {
  // The stop signals are handled on this (the loop) thread; hoist-twind's
  // main() blocks them before any helper thread exists (see main.cpp).
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  for (int sig : {SIGINT, SIGTERM, SIGQUIT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&stop_signals, sig);
  pthread_sigmask(SIG_UNBLOCK, &stop_signals, nullptr);
}

void Daemon::startSchedules() {
  start_ = Clock::now();
  cpu0_ = processCpuNanos();
  const std::size_t n = shafts_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const ServiceConfig& s = shafts_[i]->config().service;
    shafts_[i]->start(start_, static_cast<double>(i) / static_cast<double>(n) / s.health_rate);
  }
  // Every shaft announced itself (one HOIST_HEALTH each, milliseconds for
  // hundreds of shafts): the schedule starts after that burst, not under it.
  start_ = Clock::now();
  for (auto& sp : shafts_) sp->rebase(start_);
  for (auto& g : groups_) {
    g->k = 1;
    misses_.startWindow(g->window, start_, MissRecorder::threadCpuNanos());
    armTimer(*g);
  }
  misses_.startLogging();
}

void Daemon::logStarted() {
  const std::size_t n = shafts_.size();
  for (const auto& sp : shafts_) {
    const ShaftTwin& s = *sp;
    const TwinConfig& c = s.config();
    // Every channel the shaft uses (the optional ones only when configured).
    const bus::Channels& ch = s.channels();
    const bool est = c.estimator.enabled, fc = c.forecast.enabled;
    std::string ins = ch.winder + " " + ch.alarm_ack, outs = ch.cage + " " + ch.guide_shape + " " + ch.alarm + " " + ch.health;
    if (fc) ins += " " + ch.trip_plan, outs += " " + ch.forecast;
    if (est) ins += " " + ch.cage_imu + " " + ch.rope_load, outs += " " + ch.estimate;
    out_->info("{}hoist-twind {}: clock={} rate={} Hz, LCM {}{}{}, inputs {}, outputs {}, "
               "n={} modes, L={} m, h={} m, l0={} m, instance {}",
               s.tag(), n == 1 ? "started" : "shaft",
               toString(c.service.clock), c.service.rate, bus::describeLcmUrl(opt_.lcm_url),
               lcm_out_ ? ", outputs to " : "", lcm_out_ ? bus::describeLcmUrl(opt_.lcm_url_out) : std::string(),
               ins, outs, c.shaft.n, c.shaft.L, c.shaft.h, c.shaft.l0, instance_id_);
    // Whether the moment's sigma carries the accelerometer's unknown offset
    // (docs/estimation.md, "The accelerometer's offset").
    if (est) {
      const double prior = c.estimator.settings.accel_offset_sigma;
      if (prior > 0.0)
        out_->info("{}load estimator: the accelerometer's offset is estimated (uncalibrated, [sensors] "
                   "imu_accel_offset_sigma = {} m/s^2): the moment's sigma includes it until a calibration "
                   "(hoist-alarm-ack --calibrate FA,B,SECONDS with a known load)",
                   s.tag(), prior);
      else
        out_->info("{}load estimator: the accelerometer is declared calibrated ([sensors] imu_accel_offset_sigma "
                   "= 0): its offset is not estimated",
                   s.tag());
    }
  }
  if (n > 1) out_->info("hoist-twind started: {} shafts on one loop, {} schedule(s)", n, groups_.size());
}

int Daemon::run() {
  if (!start()) return 1;
  // Tell systemd (Type=notify) that the twin is up; a no-op without NOTIFY_SOCKET.
  sd_notifyf(0, "READY=1\nSTATUS=hoist-twind %s: %zu shaft(s), LCM %s", hoist::kVersionString, shafts_.size(),
             bus::describeLcmUrl(opt_.lcm_url).c_str());
  io_.run();
  return finish() ? 0 : 1;
}

bool Daemon::finish() {
  sd_notify(0, "STOPPING=1");
  watchdog_.stop();
  if (pool_) pool_->stop();
  log_.flush();
  const bool ok = writeReport();
  out_->info("hoist-twind stopped");
  out_->flush();
  return ok;
}

// ---- LCM input ---------------------------------------------------------------

void Daemon::armLcm() {
  lcm_fd_.async_wait(asio::posix::stream_descriptor::wait_read,
                     [this](const boost::system::error_code& ec) { onLcmReadable(ec); });
}

void Daemon::onLcmReadable(const boost::system::error_code& ec) {
  if (stopping_ || ec == asio::error::operation_aborted) return;
  if (ec) {
    log_.error("LCM descriptor error: {}", ec.message());
    stop("LCM error");
    return;
  }
  // Drain what is queued, bounded so the timers are never starved.
  drainInput();
  if (!stopping_) armLcm();
}

void Daemon::flushOutputs() {
  if (!sender_ || sender_->queued() == 0) return;
  const rt::ScopedSpan span(&ns_flush_, &split_.publish);
  sender_->flush();
}

void Daemon::drainInput() {
  const rt::ScopedSpan span(&ns_receive_, &split_.receive);
  input_.drain(256);
  if (const UdpmReceiver* rx = input_.udpm()) ignored_ = rx->ignored() + rx->malformed();
}

// ---- timers ------------------------------------------------------------------

void Daemon::armTimer(RateGroup& g) {
  g.timer->expires_at(start_ + g.k * g.period);
  g.timer->async_wait([this, &g](const boost::system::error_code& ec) { onTick(g, ec); });
}

void Daemon::onTick(RateGroup& g, const boost::system::error_code& ec) {
  if (ec || stopping_) return;
  progress_.fetch_add(1, std::memory_order_relaxed);  // the watchdog's proof of life
  const auto now = Clock::now();
  if (opt_.test_stall_at >= 0.0 && now - start_ >= duration<double>(opt_.test_stall_at)) [[unlikely]] {
    log_.warn("--test-stall-at: the loop thread hangs now (test only)");
    for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
  }
  // Index of the latest deadline that has passed; if it is beyond g.k the
  // ticks in between are lost (deadline misses) and the schedule skips them.
  std::int64_t k = g.k;
  std::int64_t skipped = 0;
  const std::int64_t passed = (now - start_) / g.period;
  if (passed > k) {
    skipped = passed - k;
    k = passed;
  }
  // Lateness is measured against the deadline this tick was scheduled for
  // (g.k), so a tick that misses periods reports how late it really was.
  const auto deadline = start_ + g.k * g.period;
  // Between shafts the input socket is drained every kDrainEvery shafts: a
  // tick of hundreds of shafts takes milliseconds, during which the inputs
  // of the next period arrive (no input may be lost).  An empty
  // socket costs one recvmsg.
  // The outputs queued by the shafts go out at the same points.
  // A tick that skipped deadlines is a miss: its record takes the split of
  // the loop's time since this schedule's previous tick (miss_record.hpp).
  const std::int64_t cpu_now = MissRecorder::threadCpuNanos();  // one clock_gettime per tick (not per shaft)
  const MissTick mt{g.index, g.rate, g.k, static_cast<int>(g.shafts.size())};
  MissRecord* miss = skipped > 0 ? &misses_.begin(mt, g.window, start_, now, deadline, skipped, cpu_now) : nullptr;
  misses_.startWindow(g.window, now, cpu_now);
  const std::int64_t work0 = split_.sum();
  const double period_us = duration<double, std::micro>(g.period).count();
  // Deferred starts and exact envelopes: at most the group's budgets in this tick.
  TickAllowance left{g.start_budget, g.envelope_budget};
  const auto ns_rx0 = ns_receive_, ns_fl0 = ns_flush_;
  // Staleness is judged after the inputs already queued are read: a loop
  // that wakes late (or a shaft whose tick starts late behind a slow one)
  // must not find an input stale that waits on the socket (INPUT_STALE
  // chatter, v = a = 0 fed to the twin).  So the socket is drained first,
  // and again before a shaft whose tick starts more than half a period
  // after the last drain.
  drainInput();
  auto drained_at = Clock::now();
  std::size_t i = 0;
  for (ShaftTwin* s : g.shafts) {
    s->tick(k, deadline, skipped, left);
    if (miss) [[unlikely]] MissRecorder::noteShaft(*miss, *s, g.ids[i], period_us);
    const bool every = ++i % kDrainEvery == 0;
    const auto t_now = Clock::now();
    if (every || t_now - drained_at > g.period / 2) {
      if (every) flushOutputs();
      drainInput();
      drained_at = t_now;
    }
  }
  flushOutputs();
  const std::int64_t tick_ns = nanos(Clock::now() - now);
  split_.other += std::max<std::int64_t>(0, tick_ns - (split_.sum() - work0));
  ns_ticks_ += tick_ns - (ns_receive_ - ns_rx0) - (ns_flush_ - ns_fl0);
  if (miss) misses_.commit();
  if (opt_.duration > 0.0 && duration<double>(Clock::now() - start_).count() >= opt_.duration) {
    stop("--duration elapsed");
    return;
  }
  g.k = k + 1;
  armTimer(g);
}

void Daemon::armSignals() {
  signals_.async_wait([this](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    switch (sig) {
      case SIGINT: stop("SIGINT"); return;
      case SIGTERM: stop("SIGTERM"); return;
      case SIGQUIT: stop("SIGQUIT"); return;
      case SIGHUP:
        log_.info("SIGHUP: nothing to reload or reopen (the log goes to stderr / the journal); running on");
        break;
      case SIGUSR1:
        log_.info("SIGUSR1: publishing a health report now");
        for (auto& s : shafts_) s->publishHealth();
        break;
      default: log_.info("signal {} ignored; running on", sig); break;
    }
    if (!stopping_) armSignals();
  });
}

void Daemon::stop(const char* why) {
  if (stopping_) return;
  stop_time_ = Clock::now();
  stop_reason_ = why;
  log_.info("stopping ({})", why);
  flushOutputs();
  if (trip_pool_) trip_pool_->stop();  // every room drained and closed before the shafts report them
  keepers_->stop();
  for (auto& s : shafts_) {
    s->publishHealth(true);
    s->stopOffsetKeeper();
    s->stopTrips();
    s->logFinal();
  }
  stopping_ = true;
  for (auto& g : groups_) g->timer->cancel();
  misses_.stop();
  signals_.cancel();
  if (lcm_fd_.is_open()) {
    lcm_fd_.cancel();
    lcm_fd_.release();
  }
  out_watch_.stop();
  io_.stop();
}

// ---- the run report (run_report.hpp) --------------------------------------------

bool Daemon::writeReport() const {
  if (opt_.report_path.empty()) return true;
  RunFacts f;
  f.command_line = opt_.command_line;
  f.duration_s = started_ ? duration<double>((stopping_ ? stop_time_ : Clock::now()) - start_).count() : 0.0;
  f.stop_reason = stop_reason_;
  f.realtime = rt_;
  f.log_lines_dropped = static_cast<std::int64_t>(log_.dropped());
  f.receiver = input_.udpm();
  f.sender = sender_.get();
  f.ns_ticks = ns_ticks_;
  f.ns_receive = ns_receive_;
  f.ns_flush = ns_flush_;
  f.cpu_ns = processCpuNanos() - cpu0_;
  f.misses = &misses_.log();
  for (const auto& sp : shafts_) f.shafts.push_back(sp.get());
  return writeRunReport(opt_.report_path, f, *out_);
}

}  // namespace hoist::service::app
