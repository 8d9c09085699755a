// hoist-twind's event loop: see daemon.hpp.
#include "daemon.hpp"

#include <cmath>
#include <csignal>
#include <cstdio>

#include "hoist/service/lcm_util.hpp"
#include "hoist/service/winder_decode.hpp"

namespace hoist::svc {

namespace asio = boost::asio;
using std::chrono::duration;
using std::chrono::duration_cast;

namespace {

bool finiteAll(const hoist::cage_state_t& m) {
  bool ok = std::isfinite(m.t) && std::isfinite(m.l) && std::isfinite(m.v) && std::isfinite(m.a) &&
            std::isfinite(m.x_c) && std::isfinite(m.y_c) && std::isfinite(m.theta) &&
            std::isfinite(m.y_top) && std::isfinite(m.y_bottom) &&
            std::isfinite(m.guide_deflection) && std::isfinite(m.clearance_pos_y) &&
            std::isfinite(m.clearance_neg_y) && std::isfinite(m.clearance_guide) &&
            std::isfinite(m.min_clearance);
  for (double v : m.lambda) ok = ok && std::isfinite(v);
  return ok;
}

bool finiteAll(const hoist::guide_shape_t& m) {
  bool ok = std::isfinite(m.t) && std::isfinite(m.l) && std::isfinite(m.h);
  for (int i = 0; i < m.n; ++i)
    ok = ok && std::isfinite(m.x[i]) && std::isfinite(m.y1[i]) && std::isfinite(m.y2[i]);
  return ok;
}

bool finiteAll(const hoist::alarm_t& m) {
  return std::isfinite(m.t) && std::isfinite(m.value) && std::isfinite(m.threshold) &&
         std::isfinite(m.shelved_for);
}

bool finiteAll(const hoist::health_t& m) {
  return std::isfinite(m.uptime) && std::isfinite(m.t) && std::isfinite(m.rate) &&
         std::isfinite(m.window) && std::isfinite(m.step_p50_us) && std::isfinite(m.step_p99_us) &&
         std::isfinite(m.step_max_us) && std::isfinite(m.late_p50_us) &&
         std::isfinite(m.late_p99_us) && std::isfinite(m.late_max_us) && std::isfinite(m.input_age);
}

/// A readable one-line description of an alarm event (no allocation).
void describe(const AlarmEvent& e, const AlarmConfig& cfg, double stale_timeout, char* buf,
              std::size_t n) {
  const char* verb = "";
  switch (e.type) {
    case AlarmEventType::Raise: verb = "raised"; break;
    case AlarmEventType::Clear: verb = "cleared"; break;
    case AlarmEventType::Ack: verb = "acknowledged"; break;
    case AlarmEventType::Shelve: verb = "shelved"; break;
    case AlarmEventType::Unshelve: verb = "unshelved"; break;
    case AlarmEventType::Reannounce: verb = "still active"; break;
  }
  char state[96];
  std::snprintf(state, sizeof state, "%s%s%s", e.latched ? " [latched until acknowledged]" : "",
                e.shelved ? " [shelved]" : "", (e.active && !e.acked) ? " [unacknowledged]" : "");
  switch (e.kind) {
    case AlarmKind::CagePosY:
    case AlarmKind::CageNegY:
    case AlarmKind::GuideRope: {
      const bool guide = e.kind == AlarmKind::GuideRope;
      const double gap = e.kind == AlarmKind::CagePosY   ? cfg.gap_pos_y
                         : e.kind == AlarmKind::CageNegY ? cfg.gap_neg_y
                                                         : cfg.guide_rope_gap;
      std::snprintf(buf, n, "%s %s %s: %s %.1f mm (threshold %.1f mm of gap %.1f mm, clearance %.1f mm)%s",
                    toString(e.kind), toString(e.level), verb,
                    guide ? "guide-rope deflection" : (e.kind == AlarmKind::CagePosY ? "cage excursion toward +y" : "cage excursion toward -y"),
                    e.value * 1e3, e.threshold * 1e3, gap * 1e3, (gap - e.value) * 1e3, state);
      break;
    }
    case AlarmKind::InputStale:
      std::snprintf(buf, n, "%s %s %s: no valid winder input for more than %.3g s; outputs degraded (l held, v = a = 0)%s",
                    toString(e.kind), toString(e.level), verb, stale_timeout, state);
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: winder input is back%s", toString(e.kind),
                      toString(e.level), state);
      break;
    case AlarmKind::ModelFault:
      std::snprintf(buf, n, "%s %s %s: non-finite model state, model re-initialized at static equilibrium%s",
                    toString(e.kind), toString(e.level), verb, state);
      break;
  }
}

/// At most `max` characters of `s`, non-printable ones replaced by '?' (for
/// logging strings that come from the network).
std::string printable(const std::string& s, std::size_t max = 64) {
  std::string o;
  o.reserve(std::min(s.size(), max) + 3);
  for (std::size_t i = 0; i < s.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    o.push_back(c >= 32 && c < 127 ? static_cast<char>(c) : '?');
  }
  if (s.size() > max) o += "...";
  return o;
}

int divider(double rate, double sub_rate) {
  if (!(sub_rate > 0.0)) return 1;
  return std::max(1, static_cast<int>(std::lround(rate / sub_rate)));
}

}  // namespace

Daemon::Daemon(DaemonOptions opt, std::shared_ptr<spdlog::logger> log)
    : opt_(std::move(opt)),
      log_(std::move(log)),
      ch_(opt_.cfg.service.channel_prefix),
      lcm_(opt_.lcm_url),
      lcm_fd_(io_),
      timer_(io_),
      signals_(io_, SIGINT, SIGTERM),
      core_(opt_.cfg, opt_.cfg.service.clock) {
  const ServiceConfig& s = opt_.cfg.service;
  period_ = duration_cast<Clock::duration>(duration<double>(1.0 / s.rate));
  cage_div_ = divider(s.rate, s.cage_rate);
  shape_div_ = divider(s.rate, s.shape_rate);
  health_div_ = divider(s.rate, s.health_rate);
  reject_log_.setLimit(s.log_rate_limit);

  // Preallocate every outgoing message and its buffer.
  const GuideRopeEnvelope& sh = core_.shape();
  shape_msg_.n = static_cast<int32_t>(sh.depths().size());
  shape_msg_.x.assign(sh.depths().data(), sh.depths().data() + sh.depths().size());
  shape_msg_.y1.assign(shape_msg_.n, 0.0);
  shape_msg_.y2.assign(shape_msg_.n, 0.0);
  shape_msg_.h = opt_.cfg.shaft.h;
  health_msg_.clock = toString(s.clock);
  health_msg_.rate = s.rate;
  health_msg_.n_reasons = kRejectReasons;
  health_msg_.reject_reason.resize(kRejectReasons);
  health_msg_.rejected.assign(kRejectReasons, 0);
  for (int i = 0; i < kRejectReasons; ++i)
    health_msg_.reject_reason[i] = toString(static_cast<RejectReason>(i));
  alarm_msg_.kind.reserve(64);
  alarm_msg_.message.reserve(sizeof text_);
  cage_buf_.resize(static_cast<std::size_t>(cage_msg_.getEncodedSize()) + 64);
  shape_buf_.resize(static_cast<std::size_t>(shape_msg_.getEncodedSize()) + 64);
  alarm_buf_.resize(static_cast<std::size_t>(alarm_msg_.getEncodedSize()) + 64 + sizeof text_);
  health_buf_.resize(static_cast<std::size_t>(health_msg_.getEncodedSize()) + 256);
  text_[0] = '\0';
}

Daemon::~Daemon() {
  // The descriptor belongs to LCM: never let Asio close it.
  if (lcm_fd_.is_open()) lcm_fd_.release();
}

double Daemon::wallNow() const { return duration<double>(Clock::now() - start_).count(); }

int Daemon::run() {
  const ServiceConfig& s = opt_.cfg.service;
  if (!lcm_.good()) {
    log_->error("cannot open LCM at {}; for multicast on one machine see docs/service.md "
                "(ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo)",
                describeLcmUrl(opt_.lcm_url));
    return 1;
  }
  lcm_.subscribe(ch_.winder, &Daemon::onWinder, this);
  lcm_.subscribe(ch_.ack, &Daemon::onAck, this);
  lcm_fd_.assign(lcm_.getFileno());
  armLcm();
  signals_.async_wait([this](const boost::system::error_code& ec, int sig) {
    if (!ec) stop(sig == SIGINT ? "SIGINT" : "SIGTERM");
  });
  start_ = Clock::now();
  k_ = 1;
  armTimer();
  log_->info("hoist-twind started: clock={} rate={} Hz, LCM {}, input {}, outputs {} {} {} {}, "
             "n={} modes, L={} m, h={} m, l0={} m",
             toString(s.clock), s.rate, describeLcmUrl(opt_.lcm_url), ch_.winder, ch_.cage, ch_.shape,
             ch_.alarm, ch_.health, opt_.cfg.shaft.n, opt_.cfg.shaft.L, opt_.cfg.shaft.h,
             opt_.cfg.shaft.l0);
  publishHealth();  // announce ourselves at once
  io_.run();
  log_->info("hoist-twind stopped");
  log_->flush();
  return 0;
}

// ---- LCM input ---------------------------------------------------------------

void Daemon::armLcm() {
  lcm_fd_.async_wait(asio::posix::stream_descriptor::wait_read,
                     [this](const boost::system::error_code& ec) { onLcmReadable(ec); });
}

void Daemon::onLcmReadable(const boost::system::error_code& ec) {
  if (stopping_ || ec == asio::error::operation_aborted) return;
  if (ec) {
    log_->error("LCM descriptor error: {}", ec.message());
    stop("LCM error");
    return;
  }
  // Drain what is queued, bounded so the timer is never starved.
  for (int i = 0; i < 256; ++i)
    if (lcm_.handleTimeout(0) <= 0) break;
  if (!stopping_) armLcm();
}

void Daemon::logReject(RejectReason r, const char* detail) {
  std::int64_t suppressed = 0;
  if (!reject_log_.allow(static_cast<int>(r), wallNow(), suppressed)) return;
  if (suppressed > 0)
    log_->warn("rejected winder input ({}): {} [{} similar suppressed]", toString(r), detail, suppressed);
  else
    log_->warn("rejected winder input ({}): {}", toString(r), detail);
}

void Daemon::onWinder(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  const double wall = wallNow();
  WinderSample s;
  const WinderDecode dec = decodeWinder(rbuf->data, rbuf->data_size, winder_in_, s);
  if (dec != WinderDecode::Ok) {
    core_.rejectUndecodable();
    std::snprintf(text_, sizeof text_, "%u bytes: %s", static_cast<unsigned>(rbuf->data_size), describe(dec));
    logReject(RejectReason::Decode, text_);
    return;
  }

  const auto t0 = Clock::now();
  const InputResult res = core_.onInput(s, wall);
  const auto t1 = Clock::now();
  if (!res.accepted) {
    std::snprintf(text_, sizeof text_, "seq %lld utime %lld v %g a %g%s%g",
                  static_cast<long long>(s.seq), static_cast<long long>(s.utime), s.v, s.a,
                  s.has_length ? " length " : " (no length) ", s.has_length ? s.length : 0.0);
    logReject(res.reason, text_);
  }
  if (res.reinitialized)
    log_->info("new winder stream (seq {}): model re-initialized at l = {} m", s.seq, core_.output().kin.l);
  if (res.stepped) {
    const double us = duration<double, std::micro>(t1 - t0).count();
    step_hist_.add(us);
    step_total_.add(us);
    publishCage(s.utime);
    const double rate = opt_.cfg.service.shape_rate;
    if (rate > 0.0 && core_.modelTime() - last_shape_t_ >= 1.0 / rate - 1e-9) {
      last_shape_t_ = core_.modelTime();
      publishShape(s.utime);
    }
  }
  drainAlarmEvents();
}

void Daemon::onAck(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  hoist::alarm_ack_t ack;  // operator commands are rare: allocation is fine here
  const auto size = static_cast<int>(rbuf->data_size);
  // Anyone on the group can send commands (docs/security.md): their log lines
  // are rate-limited, and the sender's strings are shortened and made
  // printable before they reach the log.
  std::int64_t suppressed = 0;
  const bool may_log = reject_log_.allow(kRejectReasons + 2, wallNow(), suppressed);
  if (may_log && suppressed > 0) log_->warn("{} alarm-command log lines suppressed", suppressed);
  if (ack.decode(rbuf->data, 0, size) != size) {
    if (may_log) log_->warn("ignored undecodable alarm command ({} bytes) on {}", size, ch_.ack);
    return;
  }
  ack.user = printable(ack.user);
  std::optional<AlarmKind> kind;
  if (!ack.kind.empty() && ack.kind != "*") {
    kind = parseAlarmKind(ack.kind);
    if (!kind) {
      if (may_log) log_->warn("ignored alarm command from '{}': unknown alarm kind '{}'", ack.user, printable(ack.kind));
      return;
    }
  }
  if (ack.level < 0 || ack.level > 2) {
    if (may_log) log_->warn("ignored alarm command from '{}': bad level {}", ack.user, int(ack.level));
    return;
  }
  const auto level = static_cast<AlarmLevel>(ack.level);
  AlarmAction action;
  switch (ack.action) {
    case hoist::alarm_ack_t::ACTION_ACK: action = AlarmAction::Ack; break;
    case hoist::alarm_ack_t::ACTION_SHELVE: action = AlarmAction::Shelve; break;
    case hoist::alarm_ack_t::ACTION_UNSHELVE: action = AlarmAction::Unshelve; break;
    default:
      if (may_log) log_->warn("ignored alarm command from '{}': bad action {}", ack.user, int(ack.action));
      return;
  }
  if (action == AlarmAction::Shelve && !(std::isfinite(ack.shelve_duration) && ack.shelve_duration > 0.0)) {
    if (may_log) log_->warn("ignored shelve from '{}': shelve_duration must be > 0 s", ack.user);
    return;
  }
  const int n = core_.command(action, kind, level, ack.shelve_duration);
  const char* what = action == AlarmAction::Ack ? "acknowledge" : action == AlarmAction::Shelve ? "shelve" : "unshelve";
  if (may_log) log_->info("operator '{}': {} {}/{}{} -> {} alarm(s)", ack.user, what,
             kind ? toString(*kind) : "*", level == AlarmLevel::None ? "*" : toString(level),
             action == AlarmAction::Shelve ? fmt::format(" for {} s", std::min(ack.shelve_duration, opt_.cfg.alarms.max_shelve)) : std::string(),
             n);
  drainAlarmEvents();
}

// ---- timer -------------------------------------------------------------------

void Daemon::armTimer() {
  timer_.expires_at(start_ + k_ * period_);
  timer_.async_wait([this](const boost::system::error_code& ec) { onTick(ec); });
}

void Daemon::onTick(const boost::system::error_code& ec) {
  if (ec || stopping_) return;
  const auto now = Clock::now();
  const auto deadline = start_ + k_ * period_;
  const double late_us = std::max(0.0, duration<double, std::micro>(now - deadline).count());
  late_hist_.add(late_us);
  late_total_.add(late_us);
  ++ticks_;
  // Index of the latest deadline that has passed; if it is beyond k_ the
  // ticks in between are lost (deadline misses) and the schedule skips them.
  std::int64_t k = k_;
  const std::int64_t passed = (now - start_) / period_;
  if (passed > k) {
    deadline_misses_ += passed - k;
    k = passed;
  }
  const double wall = duration<double>(now - start_).count();
  if (opt_.inject_fault_at >= 0.0 && !fault_injected_ && wall >= opt_.inject_fault_at) {
    fault_injected_ = true;
    log_->warn("test: injecting a model fault (non-finite state) at wall time {:.3f} s", wall);
    core_.injectFault();
  }

  if (core_.clock() == ClockMode::Wall) {
    const double t = static_cast<double>(k) / opt_.cfg.service.rate;
    const auto t0 = Clock::now();
    const TickResult r = core_.tick(t, wall);
    core_.housekeeping(wall);
    const auto t1 = Clock::now();
    if (r.stepped) {
      const double us = duration<double, std::micro>(t1 - t0).count();
      step_hist_.add(us);
      step_total_.add(us);
    }
    if (r.domain_error) {
      std::int64_t suppressed = 0;
      if (reject_log_.allow(kRejectReasons, wall, suppressed))
        log_->warn("model refused the kinematics at t = {:.3f} s (l = {:.3f} m); holding the rope length{}",
                   t, core_.output().kin.l, suppressed ? fmt::format(" [{} similar suppressed]", suppressed) : std::string());
    }
    if (r.stepped && core_.hasInput()) {
      const std::int64_t utime = wallUtime();
      if (k % cage_div_ == 0) publishCage(utime);
      if (opt_.cfg.service.shape_rate > 0.0 && k % shape_div_ == 0) publishShape(utime);
    }
  } else {
    core_.housekeeping(wall);
  }
  drainAlarmEvents();

  if (wall - last_health_wall_ >= 1.0 / opt_.cfg.service.health_rate - 0.5 / opt_.cfg.service.rate)
    publishHealth();
  if (opt_.duration > 0.0 && wall >= opt_.duration) {
    stop("--duration elapsed");
    return;
  }
  k_ = k + 1;
  armTimer();
}

void Daemon::stop(const char* why) {
  if (stopping_) return;
  log_->info("stopping ({})", why);
  publishHealth(true);
  stopping_ = true;
  timer_.cancel();
  signals_.cancel();
  lcm_fd_.cancel();
  lcm_fd_.release();
  io_.stop();
}

// ---- outputs -----------------------------------------------------------------

bool Daemon::publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len) {
  const bool injected = opt_.fail_publish_every > 0 && ++publish_attempts_ % opt_.fail_publish_every == 0;
  if (injected || lcm_.publish(channel, buf.data(), static_cast<unsigned int>(len)) != 0) {
    ++publish_failures_;
    std::int64_t suppressed = 0;
    if (reject_log_.allow(kRejectReasons + 1, wallNow(), suppressed))
      log_->error("LCM publish failed on {}{}", channel,
                  suppressed ? fmt::format(" [{} similar suppressed]", suppressed) : std::string());
    return false;
  }
  return true;
}

template <class Msg>
bool Daemon::encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf) {
  if (!finiteAll(msg)) {
    ++nonfinite_blocked_;
    std::int64_t suppressed = 0;
    if (reject_log_.allow(kRejectReasons + 1, wallNow(), suppressed))
      log_->error("withheld a message on {}: non-finite value", channel);
    return false;
  }
  const int need = msg.getEncodedSize();
  if (need > static_cast<int>(buf.size())) {
    ++publish_failures_;
    log_->error("message on {} too large for its buffer ({} > {} bytes)", channel, need, buf.size());
    return false;
  }
  const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  if (len < 0) {
    ++publish_failures_;
    return false;
  }
  return publishBytes(channel, buf, len);
}

void Daemon::publishCage(std::int64_t utime) {
  const CageOutput& o = core_.output();
  cage_msg_.utime = utime;
  cage_msg_.seq = cage_seq_++;
  cage_msg_.input_seq = o.input_seq;
  cage_msg_.t = o.t;
  cage_msg_.l = o.kin.l;
  cage_msg_.v = o.kin.v;
  cage_msg_.a = o.kin.a;
  cage_msg_.x_c = o.x_c;
  cage_msg_.y_c = o.y_c;
  cage_msg_.theta = o.theta;
  for (int i = 0; i < 5; ++i) cage_msg_.lambda[i] = o.lambda[i];
  cage_msg_.y_top = o.clearance.y_top;
  cage_msg_.y_bottom = o.clearance.y_bottom;
  cage_msg_.guide_deflection = o.clearance.guide_deflection;
  cage_msg_.clearance_pos_y = o.clearance.clearance_pos;
  cage_msg_.clearance_neg_y = o.clearance.clearance_neg;
  cage_msg_.clearance_guide = o.clearance.clearance_guide;
  cage_msg_.min_clearance = o.clearance.min_clearance;
  cage_msg_.alarm_level = static_cast<int8_t>(o.alarm_level);
  cage_msg_.degraded = o.degraded;
  encodeAndPublish(ch_.cage, cage_msg_, cage_buf_);
}

void Daemon::publishShape(std::int64_t utime) {
  core_.evaluateShape();
  const GuideRopeEnvelope& sh = core_.shape();
  shape_msg_.utime = utime;
  shape_msg_.t = core_.output().t;
  shape_msg_.l = core_.output().kin.l;
  for (int i = 0; i < shape_msg_.n; ++i) {
    shape_msg_.y1[i] = sh.y1()(i);
    shape_msg_.y2[i] = sh.y2()(i);
  }
  encodeAndPublish(ch_.shape, shape_msg_, shape_buf_);
}

void Daemon::drainAlarmEvents() {
  const AlarmEvents& ev = core_.events();
  if (ev.empty()) return;
  const std::int64_t utime = wallUtime();
  for (const AlarmEvent& e : ev) {
    describe(e, opt_.cfg.alarms, core_.staleTimeout(), text_, sizeof text_);
    alarm_msg_.utime = utime;
    alarm_msg_.id = alarm_id_++;
    alarm_msg_.t = e.t;
    alarm_msg_.kind.assign(toString(e.kind));
    alarm_msg_.level = static_cast<int8_t>(e.level);
    alarm_msg_.event = static_cast<int8_t>(e.type);
    alarm_msg_.active = e.active;
    alarm_msg_.acked = e.acked;
    alarm_msg_.shelved = e.shelved;
    alarm_msg_.latched = e.latched;
    alarm_msg_.value = e.value;
    alarm_msg_.threshold = e.threshold;
    alarm_msg_.shelved_for = e.shelved_for;
    alarm_msg_.message.assign(text_);
    if (encodeAndPublish(ch_.alarm, alarm_msg_, alarm_buf_)) ++alarm_events_;
    switch (e.type) {
      case AlarmEventType::Reannounce: log_->debug("alarm: {} (t = {:.2f} s)", text_, e.t); break;
      case AlarmEventType::Raise:
        if (e.level == AlarmLevel::Critical) log_->error("ALARM {} (t = {:.2f} s)", text_, e.t);
        else log_->warn("ALARM {} (t = {:.2f} s)", text_, e.t);
        break;
      default: log_->info("alarm: {} (t = {:.2f} s)", text_, e.t); break;
    }
  }
  if (ev.dropped() > 0) log_->error("{} alarm events dropped (event buffer full)", ev.dropped());
  core_.clearEvents();
}

void Daemon::publishHealth(bool final_report) {
  const double wall = wallNow();
  const InputCounters& c = core_.counters();
  const AlarmEngine& al = core_.alarms();
  health_msg_.utime = wallUtime();
  health_msg_.uptime = wall;
  health_msg_.t = core_.modelTime();
  health_msg_.window = wall - last_health_wall_;
  health_msg_.ticks = ticks_;
  health_msg_.steps = core_.steps();
  health_msg_.deadline_misses = deadline_misses_;
  health_msg_.step_p50_us = step_hist_.quantile(0.5);
  health_msg_.step_p99_us = step_hist_.quantile(0.99);
  health_msg_.step_max_us = step_hist_.max();
  health_msg_.late_p50_us = late_hist_.quantile(0.5);
  health_msg_.late_p99_us = late_hist_.quantile(0.99);
  health_msg_.late_max_us = late_hist_.max();
  health_msg_.input_age = core_.inputAge(wall);
  health_msg_.accepted = c.accepted;
  health_msg_.seq_gaps = c.seq_gaps;
  health_msg_.rejected_total = c.rejectedTotal();
  for (int i = 0; i < kRejectReasons; ++i) health_msg_.rejected[i] = c.rejected[i];
  health_msg_.alarms_active = al.activeCount();
  health_msg_.alarms_unacked = al.unackedCount();
  health_msg_.alarms_shelved = al.shelvedCount();
  health_msg_.alarm_events = alarm_events_;
  health_msg_.model_faults = core_.modelFaults();
  health_msg_.model_resets = core_.modelResets();
  health_msg_.publish_failures = publish_failures_;
  health_msg_.nonfinite_blocked = nonfinite_blocked_;
  health_msg_.degraded = core_.degraded();
  encodeAndPublish(ch_.health, health_msg_, health_buf_);

  auto line = [&](spdlog::level::level_enum lvl) {
    log_->log(lvl,
              "{}health: t={:.2f} s steps={} step p50/p99/max={:.0f}/{:.0f}/{:.0f} us late "
              "p50/p99/max={:.0f}/{:.0f}/{:.0f} us misses={} inputs ok={} rejected={} gaps={} "
              "alarms active={} faults={} publish failures={}{}",
              final_report ? "final " : "", health_msg_.t, health_msg_.steps, health_msg_.step_p50_us,
              health_msg_.step_p99_us, health_msg_.step_max_us, health_msg_.late_p50_us,
              health_msg_.late_p99_us, health_msg_.late_max_us, deadline_misses_, c.accepted,
              c.rejectedTotal(), c.seq_gaps, health_msg_.alarms_active, health_msg_.model_faults,
              publish_failures_, health_msg_.degraded ? " DEGRADED" : "");
  };
  if (final_report) {
    log_->info("final health: t={:.2f} s ticks={} steps={} over the whole run: step p50/p99/max="
               "{:.0f}/{:.0f}/{:.0f} us, tick lateness p50/p99/max={:.0f}/{:.0f}/{:.0f} us, "
               "deadline misses={}; inputs accepted={} rejected={} sequence gaps={}; alarms "
               "active={} events={}; model faults={} resets={}; publish failures={} withheld "
               "(non-finite)={}{}",
               health_msg_.t, ticks_, health_msg_.steps, step_total_.quantile(0.5),
               step_total_.quantile(0.99), step_total_.max(), late_total_.quantile(0.5),
               late_total_.quantile(0.99), late_total_.max(), deadline_misses_, c.accepted,
               c.rejectedTotal(), c.seq_gaps, health_msg_.alarms_active, alarm_events_,
               health_msg_.model_faults, health_msg_.model_resets, publish_failures_,
               nonfinite_blocked_, health_msg_.degraded ? " DEGRADED" : "");
    for (int i = 0; i < kRejectReasons; ++i)
      if (c.rejected[i] > 0)
        log_->info("  rejected {}: {}", toString(static_cast<RejectReason>(i)), c.rejected[i]);
  } else {
    line(spdlog::level::debug);
  }
  step_hist_.reset();
  late_hist_.reset();
  last_health_wall_ = wall;
}

}  // namespace hoist::svc
