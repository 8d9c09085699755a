// hoist-twind's event loop: see daemon.hpp.
#include "daemon.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <unistd.h>

#include "hoist/bus/lcm_util.hpp"

namespace hoist::svc {

namespace asio = boost::asio;
using std::chrono::duration;
using std::chrono::duration_cast;

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
    lcm_out_ = std::make_unique<lcm::LCM>(opt_.lcm_url_out);
  opt_.labels.resize(opt_.shafts.size());
  // One ShaftTwin per configuration, one schedule (timer) per distinct rate.
  std::map<double, RateGroup*> by_rate;
  for (std::size_t i = 0; i < opt_.shafts.size(); ++i) {
    shafts_.push_back(std::make_unique<ShaftTwin>(opt_.shafts[i], opt_.labels[i], lcm_, log_, opt_.hooks,
                                                  instance_id_, lcm_out_.get()));
    const double rate = opt_.shafts[i].service.rate;
    RateGroup*& g = by_rate[rate];
    if (!g) {
      groups_.push_back(std::make_unique<RateGroup>());
      g = groups_.back().get();
      g->rate = rate;
      g->period = duration_cast<Clock::duration>(duration<double>(1.0 / rate));
      g->timer = std::make_unique<asio::steady_timer>(io_);
    }
    g->shafts.push_back(shafts_.back().get());
  }
  for (auto& g : groups_) g->shafts.shrink_to_fit();
}

Daemon::~Daemon() {
  // The descriptor belongs to LCM: never let Asio close it.
  if (lcm_fd_.is_open()) lcm_fd_.release();
  log_.stop();
}

bool Daemon::start() {
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
  rt_ = applyRealtime(opt_.realtime);
  (rt_.all_granted ? out_->info("real-time settings: {}", rt_.summary())
                   : out_->warn("real-time settings: {} (running without them)", rt_.summary()));
  // udpm:// (and LCM's default): our own receive path, which dispatches only
  // the subscribed channels by exact name and stores nothing per channel
  // name seen (LCM 1.3.1 would; udpm_receiver.hpp).  Other providers go
  // through LCM (literal names, regex-escaped).
  UdpmUrl udpm;
  std::string why;
  if (parseUdpmUrl(opt_.lcm_url, udpm, why)) {
    receiver_ = std::make_unique<UdpmReceiver>();
    if (!receiver_->open(udpm, why)) {
      out_->error("cannot open the LCM input socket for {}: {}", bus::describeLcmUrl(opt_.lcm_url), why);
      return false;
    }
    for (auto& s : shafts_) {
      s->subscribe(receiver_.get());
      s->setIgnoredCounter(&ignored_);
    }
    lcm_fd_.assign(receiver_->fd());
  } else {
    for (auto& s : shafts_) s->subscribe();
    lcm_fd_.assign(lcm_.getFileno());
  }
  armLcm();
  // The stop signals are handled on this (the loop) thread; hoist-twind's
  // main() blocks them before any helper thread exists (see main.cpp).
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  for (int sig : {SIGINT, SIGTERM, SIGQUIT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&stop_signals, sig);
  pthread_sigmask(SIG_UNBLOCK, &stop_signals, nullptr);
  armSignals();
  start_ = Clock::now();
  const std::size_t n = shafts_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const ServiceConfig& s = shafts_[i]->config().service;
    shafts_[i]->start(start_, static_cast<double>(i) / static_cast<double>(n) / s.health_rate);
  }
  for (auto& g : groups_) {
    g->k = 1;
    armTimer(*g);
  }
  for (const auto& sp : shafts_) {
    const ShaftTwin& s = *sp;
    const TwinConfig& c = s.config();
    out_->info("{}hoist-twind {}: clock={} rate={} Hz, LCM {}{}{}, input {}, outputs {} {} {} {}, "
               "n={} modes, L={} m, h={} m, l0={} m, instance {}",
               s.tag(), n == 1 ? "started" : "shaft",
               toString(c.service.clock), c.service.rate, bus::describeLcmUrl(opt_.lcm_url),
               lcm_out_ ? ", outputs to " : "", lcm_out_ ? bus::describeLcmUrl(opt_.lcm_url_out) : std::string(),
               s.channels().winder, s.channels().cage, s.channels().shape, s.channels().alarm,
               s.channels().health, c.shaft.n, c.shaft.L, c.shaft.h, c.shaft.l0, instance_id_);
  }
  if (n > 1) out_->info("hoist-twind started: {} shafts on one loop, {} schedule(s)", n, groups_.size());
  started_ = true;
  return true;
}

int Daemon::run() {
  if (!start()) return 1;
  io_.run();
  return finish() ? 0 : 1;
}

bool Daemon::finish() {
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
  if (receiver_) {
    receiver_->drain(256);
    ignored_ = receiver_->ignored() + receiver_->malformed();
  } else {
    for (int i = 0; i < 256; ++i)
      if (lcm_.handleTimeout(0) <= 0) break;
  }
  if (!stopping_) armLcm();
}

// ---- timers ------------------------------------------------------------------

void Daemon::armTimer(RateGroup& g) {
  g.timer->expires_at(start_ + g.k * g.period);
  g.timer->async_wait([this, &g](const boost::system::error_code& ec) { onTick(g, ec); });
}

void Daemon::onTick(RateGroup& g, const boost::system::error_code& ec) {
  if (ec || stopping_) return;
  const auto now = Clock::now();
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
  for (ShaftTwin* s : g.shafts) s->tick(k, deadline, skipped);
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
  for (auto& s : shafts_) {
    s->publishHealth(true);
    s->logFinal();
  }
  stopping_ = true;
  for (auto& g : groups_) g->timer->cancel();
  signals_.cancel();
  if (lcm_fd_.is_open()) {
    lcm_fd_.cancel();
    lcm_fd_.release();
  }
  io_.stop();
}

// ---- the run report ------------------------------------------------------------

namespace {
std::string jsonString(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 32) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", c);
      o += b;
    } else {
      o += c;
    }
  }
  return o + "\"";
}

void histogramJson(std::ostream& os, const LatencyHistogram& h) {
  os << "{\"count\": " << h.count() << ", \"p50\": " << h.quantile(0.5) << ", \"p99\": " << h.quantile(0.99)
     << ", \"p999\": " << h.quantile(0.999) << ", \"max\": " << h.max() << ", \"bins\": [";
  bool first = true;
  for (int b = 0; b < LatencyHistogram::kBins; ++b) {
    if (h.binCount(b) == 0) continue;
    os << (first ? "" : ", ") << "[" << LatencyHistogram::binLowerUs(b) << ", " << h.binCount(b) << "]";
    first = false;
  }
  os << "]}";
}
}  // namespace

bool Daemon::writeReport() const {
  if (opt_.report_path.empty()) return true;
  std::ostringstream os;
  os.precision(6);
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const double ran = started_ ? duration<double>((stopping_ ? stop_time_ : Clock::now()) - start_).count() : 0.0;
  os << "{\n  \"tool\": \"hoist-twind\",\n  \"command\": " << jsonString(opt_.command_line)
     << ",\n  \"host\": " << jsonString(host) << ",\n  \"date\": " << jsonString(date)
     << ",\n  \"cpus_online\": " << sysconf(_SC_NPROCESSORS_ONLN) << ",\n  \"duration_s\": " << ran
     << ",\n  \"stop_reason\": " << jsonString(stop_reason_)
     << ",\n  \"realtime\": {\"memory_lock\": " << jsonString(rt_.mlockall)
     << ", \"scheduling\": " << jsonString(rt_.scheduling) << ", \"affinity\": " << jsonString(rt_.affinity)
     << "},\n  \"log_lines_dropped\": " << log_.dropped() << ",\n  \"histogram_note\": "
     << jsonString("times in microseconds; " + std::to_string(LatencyHistogram::kPerDecade) +
                   " logarithmic bins per decade from 0.1 us, so quantiles are bin centres (about 1.2 % "
                   "resolution); bins are [lower edge, count]")
     << ",\n  \"shafts\": [\n";
  for (std::size_t i = 0; i < shafts_.size(); ++i) {
    const ShaftRunStats s = shafts_[i]->runStats();
    const TwinConfig& c = shafts_[i]->config();
    os << "    {\"label\": " << jsonString(s.label) << ", \"channel_prefix\": "
       << jsonString(c.service.channel_prefix) << ", \"clock\": " << jsonString(toString(c.service.clock))
       << ", \"rate_hz\": " << c.service.rate << ", \"modes\": " << c.shaft.n << ", \"ticks\": " << s.ticks
       << ", \"steps\": " << s.steps << ", \"deadline_misses\": " << s.deadline_misses
       << ", \"inputs_accepted\": " << s.accepted << ", \"inputs_rejected\": " << s.rejected
       << ", \"sequence_gaps\": " << s.seq_gaps << ", \"alarm_events\": " << s.alarm_events
       << ", \"model_faults\": " << s.model_faults << ", \"publish_failures\": " << s.publish_failures
       << ", \"nonfinite_withheld\": " << s.nonfinite_blocked << ",\n     \"step_us\": ";
    histogramJson(os, *s.step);
    os << ",\n     \"late_us\": ";
    histogramJson(os, *s.late);
    os << "}" << (i + 1 < shafts_.size() ? "," : "") << "\n";
  }
  os << "  ]\n}\n";
  const std::string tmp = opt_.report_path + ".tmp";
  {
    std::ofstream f(tmp);
    f << os.str();
    if (!f) {
      out_->error("cannot write the run report {}", opt_.report_path);
      return false;
    }
  }
  if (std::rename(tmp.c_str(), opt_.report_path.c_str()) != 0) {
    out_->error("cannot write the run report {}", opt_.report_path);
    return false;
  }
  out_->info("run report written to {}", opt_.report_path);
  return true;
}

}  // namespace hoist::svc
