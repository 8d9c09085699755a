// One shaft's memory: see trip_room.hpp.
#include "trip_room.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "hoist/history/condition_judge.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/history/store.hpp"
#include "hoist/trip_recorder.hpp"

namespace hoist::service::inline app {

namespace {

std::int64_t threadCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

std::shared_ptr<spdlog::logger> logger() {
  auto l = spdlog::get("hoist-twind");
  return l ? l : spdlog::default_logger();
}

/// [condition] plus what the daemon's other sections say ([alarms] gaps).
ConditionSettings conditionFor(const TwinConfig& cfg, const TripHistoryConfig& h) {
  ConditionSettings c = h.condition;
  // The preload fit carries the accelerometer's offset as the twin's
  // estimator does (its [sensors] imu_accel_offset_sigma).
  c.accel_offset_sigma = cfg.estimator.settings.accel_offset_sigma;
  c.clearance.gap_pos_y = cfg.alarms.gap_pos_y;
  c.clearance.gap_neg_y = cfg.alarms.gap_neg_y;
  c.clearance.guide_rope_gap = cfg.alarms.guide_rope_gap;
  c.clearance.warning_fraction = cfg.alarms.warning_fraction;
  c.clearance.critical_fraction = cfg.alarms.critical_fraction;
  return c;
}
}  // namespace

// ---- the ring --------------------------------------------------------------

TripRing::TripRing(std::size_t capacity) : buf_(capacity) {
  if (capacity < 2) throw std::invalid_argument("TripRing: capacity must be >= 2");
}

bool TripRing::push(const TripTick& t) {
  const std::size_t h = head_.load(std::memory_order_relaxed);
  const std::size_t next = (h + 1) % buf_.size();
  if (next == tail_.load(std::memory_order_acquire)) return false;  // full
  buf_[h] = t;
  head_.store(next, std::memory_order_release);
  return true;
}

bool TripRing::pop(TripTick& out) {
  const std::size_t t = tail_.load(std::memory_order_relaxed);
  if (t == head_.load(std::memory_order_acquire)) return false;  // empty
  out = buf_[t];
  tail_.store((t + 1) % buf_.size(), std::memory_order_release);
  return true;
}

// ---- the room --------------------------------------------------------------

struct TripRoom::Worker {
  Worker(const TwinConfig& cfg, const ConditionSettings& cond)
      : rec(cfg.shaft, cfg.estimator.settings, cond, cfg.service.max_step), judge(cond), cond_settings(cond) {}
  TripRecorder rec;
  history::ConditionJudge judge;  // GUIDE_PRELOAD_LOW, SHAFT_FINGERPRINT over the shaft's trips
  ConditionSettings cond_settings;
  std::unique_ptr<history::Store> store;
  std::uint32_t seen = 0;        // alarm kinds already added to the trip under way
  TripTick tick;                 // the tick being taken
  std::int64_t cpu_trip0 = 0;    // the room's CPU (roomCpu) at the trip's first tick
  std::int64_t drain_c0 = 0;     // the worker thread's CPU when this drain began
  bool moving = false;
  std::int64_t detect_trip = 0;     // the last recorded trip (ConditionState)
  double loss30_separation = -1.0;
  bool loss30_visible = false;
  std::int64_t verdicts = 0;        // trips that judged the twin's preload (ConditionState::verdict_trip)
  PreloadVerdict verdict;           // the last of them
};

TripRoom::TripRoom(const TwinConfig& cfg, const TripHistoryConfig& hist, std::string shaft_name, std::size_t capacity)
    : cfg_(cfg),
      hist_(hist),
      shaft_(std::move(shaft_name)),
      tag_(shaft_.empty() ? std::string() : "[" + shaft_ + "] "),
      ring_(capacity ? capacity
                     : std::max<std::size_t>(1024, static_cast<std::size_t>(30.0 * cfg.service.rate))),
      w_(std::make_unique<Worker>(cfg, conditionFor(cfg, hist))) {}

TripRoom::~TripRoom() = default;

void TripRoom::afterStep(const TwinCore& core, std::int64_t wall_us) {
  TripTick& t = scratch_;
  const CageOutput& o = core.output();
  if (const LoadEstimate* e = core.estimate()) {
    t.e = tripEstimate(*e);
    t.m = core.lastMeasurement();
  } else {
    t.e = TripEstimate{};
    t.e.y_c = o.y_c;
    t.e.theta = o.theta;
    t.e.lambda = o.lambda;
    t.m = MeasurementSample{};
  }
  t.m.t = core.modelTime();
  t.m.k = o.kin;
  t.guide_deflection = o.clearance.guide_deflection;
  t.wall_us = wall_us;
  std::uint32_t bits = 0;
  for (const BinaryAlarm& a : core.alarms().alarms())
    if (a.active()) bits |= 1u << static_cast<unsigned>(a.kind());
  t.alarms = bits;
  t.twin_preload_scale = core.preloadScale();
  if (ring_.push(t)) counts_.ticks.fetch_add(1, std::memory_order_relaxed);
  else counts_.dropped.fetch_add(1, std::memory_order_relaxed);
}

std::string TripRoom::describeStore() const {
  return counts_.store_open.load(std::memory_order_acquire) ? store_desc_ : std::string();
}

void TripRoom::workerOpen() {
  auto log = logger();
  const std::string& tag = tag_;
  try {
    history::HistoryConfig h = hist_.store;
    const history::StoreOptions o = history::resolveStoreOptions(h, hist_.config_dir);
    w_->store = history::openStore(o);
    store_desc_ = w_->store->describe();
    counts_.store_open.store(true, std::memory_order_release);
    log->info("{}trip history: recording every trip into {} (schema {})", tag, store_desc_,
              w_->store->schemaVersion());
    pruneOld(std::chrono::duration_cast<std::chrono::microseconds>(
                 std::chrono::system_clock::now().time_since_epoch()).count());
  } catch (const std::exception& e) {
    log->error("{}trip history: the database cannot be opened: {}; trips are detected and counted but not "
               "stored (the twin runs on)", tag, e.what());
  }
  if (w_->store) {
    try {
      const std::int64_t n = w_->judge.seed(*w_->store, shaft_);
      if (w_->judge.seededWindowed())
        log->info("{}shaft condition from {} stored trips (the newest [condition] seed_trips up to trip {} and the "
                  "baseline before them): {}", tag, n, w_->judge.storedLastTrip(), w_->judge.summary());
      else
        log->info("{}shaft condition from {} stored trips: {}", tag, n, w_->judge.summary());
    } catch (const std::exception& e) {
      log->error("{}shaft condition: the stored trips cannot be read ({}): GUIDE_PRELOAD_LOW and SHAFT_FINGERPRINT "
                 "are judged from this run's trips only", tag, e.what());
    }
    // The stored trend against the configuration's preload (the loop uses
    // the verdict only if its twin runs that scale: not after a kept adoption).
    if (w_->judge.preload().valid)
      noteVerdict(PreloadVerdict{}, judgeTrendPreload(w_->judge.preload(), 1.0, w_->cond_settings.model_check_sigma), 0);
  }
  publishCondition();
}

void TripRoom::workerDrain() {
  Worker& w = *w_;
  w.drain_c0 = threadCpuNs();
  while (ring_.pop(w.tick)) take(w.tick);
  counts_.cpu_ns.fetch_add(threadCpuNs() - w.drain_c0, std::memory_order_relaxed);
}

void TripRoom::workerClose() {
  if (!w_->store) return;
  try {
    w_->store->flush();
  } catch (const std::exception& e) {
    logger()->warn("{}trip history: flush at stop: {}", tag_, e.what());
  }
}

std::int64_t TripRoom::roomCpu() const {
  // This room's worker CPU so far, the drain under way included (a pool
  // thread also serves other rooms: its own clock is not this room's).
  return counts_.cpu_ns.load(std::memory_order_relaxed) + (threadCpuNs() - w_->drain_c0);
}

void TripRoom::publishCondition() {
  const Worker& w = *w_;
  ConditionState& c = condition_.writeSlot();
  const PreloadDecision p = w.judge.preload();
  const FingerprintDecision f = w.judge.fingerprint();
  c.preload = static_cast<AlarmLevel>(static_cast<int>(p.level));
  c.upper95 = p.valid ? p.upper95 : 0.0;
  c.warning = w.cond_settings.preload_warning;
  c.critical = w.cond_settings.preload_critical;
  c.fingerprint = f.active;
  c.z = f.hits.empty() ? 0.0 : f.hits.front().z_last;
  c.z_limit = w.cond_settings.fingerprint_sigma;
  c.trips = w.judge.trips();
  c.detect_trip = w.detect_trip;
  c.loss30_separation = w.loss30_separation;
  c.loss30_visible = w.loss30_visible;
  c.verdict_trip = w.verdicts;
  c.verdict_mismatch = w.verdict.mismatch;
  c.verdict_z = w.verdict.z;
  c.verdict_limit = w.verdict.limit;
  c.verdict_twin_scale = w.verdict.twin_scale;
  describe(w.verdict, c.verdict_text.data(), c.verdict_text.size());
  std::snprintf(c.preload_text.data(), c.preload_text.size(), "%s", p.text.c_str());
  std::snprintf(c.fingerprint_text.data(), c.fingerprint_text.size(), "%s", f.text.c_str());
  condition_.publish();
  counts_.judged.store(true, std::memory_order_release);
}

bool TripRoom::noteVerdict(const PreloadVerdict& trip, const PreloadVerdict& trend, std::int64_t number) {
  Worker& w = *w_;
  // MODEL_MISMATCH when either fires (the stronger one's text); else the
  // trip's own consistent verdict, else the trend's; else nothing new.
  const PreloadVerdict* v = nullptr;
  if (trip.mismatch && trend.mismatch) v = std::abs(trip.z) >= std::abs(trend.z) ? &trip : &trend;
  else if (trip.mismatch) v = &trip;
  else if (trend.mismatch) v = &trend;
  else if (trip.judged) v = &trip;
  else if (trend.judged) v = &trend;
  if (!v) return false;
  const bool was = w.verdicts > 0 && w.verdict.mismatch;
  w.verdict = *v;
  ++w.verdicts;
  char text[320];
  describe(*v, text, sizeof text);
  const std::string& tag = tag_;
  auto log = logger();
  const std::string when = number > 0 ? "trip " + std::to_string(number) : std::string("the stored trips");
  if (v->mismatch || was)
    log->warn("{}{}: {}{}", tag, when, text,
              v->mismatch ? ": MODEL_MISMATCH" : ": MODEL_MISMATCH's trip-end test passes again");
  else
    log->info("{}{}: {}", tag, when, text);
  return true;
}

void TripRoom::pruneOld(std::int64_t now_us) {
  const int keep_days = hist_.store.keep_days;
  if (keep_days <= 0 || !w_->store) return;
  const std::string& tag = tag_;
  try {
    const std::int64_t pruned = w_->store->prune(keep_days, now_us);
    if (pruned > 0) logger()->info("{}trip history: {} trips older than history.keep_days = {} pruned", tag, pruned, keep_days);
  } catch (const std::exception& e) {
    logger()->warn("{}trip history: pruning trips older than history.keep_days = {} failed: {}", tag, keep_days, e.what());
  }
}

void TripRoom::take(const TripTick& t) {
  Worker& w = *w_;
  // A tick without a finite state (no input yet, a model fault) is no part of a trip.
  if (!std::isfinite(t.m.t) || !std::isfinite(t.m.k.l) || !std::isfinite(t.m.k.v) || !std::isfinite(t.m.k.a) ||
      !std::isfinite(t.e.y_c) || !std::isfinite(t.e.theta))
    return;
  if (!w.moving) w.cpu_trip0 = roomCpu();
  bool arrived = false;
  try {
    arrived = w.rec.add(t.m, t.e, t.guide_deflection);
  } catch (const std::exception& e) {
    // A step the identification's solver refused: this trip is lost, the next one starts afresh.
    counts_.failed.fetch_add(1, std::memory_order_relaxed);
    logger()->warn("{}trip history: a trip's record failed: {}", tag_, e.what());
    w.rec.reset();
    w.moving = false;
    w.seen = 0;
    return;
  }
  if (w.rec.moving()) {
    w.moving = true;
    const std::uint32_t fresh = t.alarms & ~w.seen;
    if (fresh) {
      for (int k = 0; k < contract::kAlarmKinds; ++k)
        if (fresh & (1u << k)) w.rec.addAlarm(contract::toString(static_cast<AlarmKind>(k)));
      w.seen |= fresh;
    }
  }
  counts_.not_a_trip.store(w.rec.notATrip(), std::memory_order_relaxed);
  if (arrived) finishTrip();
  if (!w.rec.moving()) {
    w.moving = false;
    w.seen = t.alarms;  // raised before the departure: not counted unless raised again
  }
}

void TripRoom::finishTrip() {
  Worker& w = *w_;
  TripRecord& r = w.rec.record();
  const TripTick& now = w.tick;
  r.shaft = shaft_;
  // Wall clock: the tick's wall time, shifted by the model-time difference.
  auto wallAt = [&now](double t_model) {
    return now.wall_us - static_cast<std::int64_t>(std::llround((now.m.t - t_model) * 1e6));
  };
  r.wall_start_us = wallAt(r.t_start);
  r.wall_end_us = wallAt(r.t_end);
  counts_.trips.fetch_add(1, std::memory_order_relaxed);
  const std::int64_t cpu = roomCpu() - w.cpu_trip0;
  counts_.cpu_ns_last.store(cpu, std::memory_order_relaxed);
  auto log = logger();
  const std::string& tag = tag_;
  // The condition alarms, judged before the record is stored (its alarms
  // name them).  The judge needs the trip's number: the store's next one.
  std::int64_t number = 0;
  if (w.store) {
    try {
      number = w.store->nextTrip(shaft_);
    } catch (const std::exception& e) {
      log->warn("{}trip history: the next trip number cannot be read ({}); the store numbers the record", tag,
                e.what());
    }
  }
  r.trip = number > 0 ? number : w.judge.lastTrip() + 1;
  // MODEL_MISMATCH's trip-end test: this trip's preload against the twin's
  // (and, once the judge has it, the shaft's trend: noteVerdict).
  const PreloadVerdict v = judgeTripPreload(r.id, now.twin_preload_scale, w.cond_settings.model_check_sigma);
  bool noted = false;
  try {  // never out of the worker: a record the judge refuses is logged, the trip still stored
    const ConditionLevel before = w.judge.preload().level;
    const bool finger_before = w.judge.fingerprint().active;
    w.judge.judge(r);
    w.detect_trip = r.trip;
    w.loss30_separation = r.id.attempted ? r.id.loss30_separation : 0.0;
    w.loss30_visible = r.id.informative;
    noted = noteVerdict(v, judgeTrendPreload(w.judge.preload(), now.twin_preload_scale,
                                             w.cond_settings.model_check_sigma),
                        r.trip);
    publishCondition();
    if (w.judge.preload().level != before || w.judge.fingerprint().active != finger_before)
      log->warn("{}shaft condition changed after trip {}: {}", tag, r.trip, w.judge.summary());
  } catch (const std::exception& e) {
    log->error("{}shaft condition: trip {} could not be judged ({}); the condition alarms stay as they were", tag,
               r.trip, e.what());
    if (!noted && noteVerdict(v, PreloadVerdict{}, r.trip))
      publishCondition();  // the trip's own verdict still reaches the loop
  }
  if (number <= 0) r.trip = 0;
  if (!w.store) {
    counts_.failed.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  try {
    const history::PutResult p = w.store->put(r);
    if (p == history::PutResult::Queued) counts_.queued.fetch_add(1, std::memory_order_relaxed);
    else counts_.stored.fetch_add(1, std::memory_order_relaxed);
    char scale[96];
    if (r.id.attempted && r.id.sigma_scale >= 0.0)
      std::snprintf(scale, sizeof scale, "preload scale %.3f +- %.3f%s", r.id.scale, r.id.sigma_scale,
                    r.id.informative ? "" : " (not informative)");
    else
      std::snprintf(scale, sizeof scale, "preload scale not identified");
    log->info("{}trip {} recorded ({}): {} {:.1f} -> {:.1f} m, {}, alarms: {}, {:.0f} ms CPU", tag, r.trip,
              history::toString(p), r.direction == TripDirection::Down ? "down" : "up", r.depth_start, r.depth_end,
              scale, r.alarms.empty() ? std::string("none") : history::joinAlarms(r.alarms), cpu * 1e-6);
    pruneOld(now.wall_us);  // a daemon that runs for months keeps keep_days too
  } catch (const std::exception& e) {
    counts_.failed.fetch_add(1, std::memory_order_relaxed);
    log->error("{}trip history: the record of a trip could not be written: {}", tag, e.what());
  }
}

}  // namespace hoist::service::app
