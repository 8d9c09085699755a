// One shaft's adopted guide-rope preload: see preload_keeper.hpp.
#include "preload_keeper.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>

#include "hoist/contract/alarm_command.hpp"
#include "hoist/io/preload_file.hpp"

namespace hoist::service::inline app {

PreloadKeeper::PreloadKeeper(const TwinConfig& nominal, std::string path, std::string tag,
                             std::shared_ptr<spdlog::logger> log, rt::RtLog& rt_log)
    : nominal_(nominal), path_(std::move(path)), tag_(std::move(tag)), log_(std::move(log)), rt_log_(rt_log) {}

PreloadKeeper::~PreloadKeeper() {
  delete ready_.exchange(nullptr);
  delete retired_.exchange(nullptr);
}

std::unique_ptr<TwinModel> PreloadKeeper::loadKept() {
  std::error_code ec;
  if (path_.empty() || !std::filesystem::exists(path_, ec)) return nullptr;
  io::PreloadRecord r;
  try {
    r = io::readPreloadFile(path_);
  } catch (const std::exception& e) {
    log_->error("{}guide-rope preload: {} is damaged and ignored ({}); the twin runs the config's preloads until "
                "an operator adopts one again", tag_, path_, e.what());
    return nullptr;
  }
  if (!(r.preload_scale >= contract::kMinPreloadScale && r.preload_scale <= contract::kMaxPreloadScale)) {
    log_->error("{}guide-rope preload: {} holds preload_scale = {}, outside [{}, {}]: ignored; the twin runs the "
                "config's preloads", tag_, path_, r.preload_scale, contract::kMinPreloadScale,
                contract::kMaxPreloadScale);
    return nullptr;
  }
  if (r.preload_scale == 1.0) return nullptr;
  try {
    auto m = buildTwinModel(nominal_, r.preload_scale);
    log_->warn("{}guide-rope preload: the twin runs the preloads x{} (Tb1 = {:.0f} N, Tb2 = {:.0f} N; the config "
               "says {:.0f} N and {:.0f} N), adopted by '{}' at utime {}, kept in {}", tag_, r.preload_scale,
               m->shaft.Tb1, m->shaft.Tb2, nominal_.shaft.Tb1, nominal_.shaft.Tb2, r.adopted_by, r.adopted_utime,
               path_);
    return m;
  } catch (const std::exception& e) {
    log_->error("{}guide-rope preload: the kept x{} gives a model the twin refuses ({}): the twin runs the "
                "config's preloads", tag_, r.preload_scale, e.what());
    return nullptr;
  }
}

bool PreloadKeeper::request(double scale, const std::string& user, std::int64_t utime) {
  bool expected = false;
  if (!busy_.compare_exchange_strong(expected, true, std::memory_order_acq_rel)) return false;
  Request& r = requests_.writeSlot();
  r.scale = scale;
  r.utime = utime;
  const std::size_t n = std::min(user.size(), r.user.size() - 1);
  std::memcpy(r.user.data(), user.data(), n);
  r.user[n] = '\0';
  requests_.publish();
  waiting_logged_ = false;
  return true;
}

void PreloadKeeper::serve() {
  if (Built* done = retired_.exchange(nullptr, std::memory_order_acq_rel)) {
    delete done;  // the model the loop ran before
    busy_.store(false, std::memory_order_release);
  }
  const Request* r = requests_.take();
  if (!r) return;
  auto built = std::make_unique<Built>();
  built->req = *r;
  try {
    built->model = buildTwinModel(nominal_, r->scale);
  } catch (const std::exception& e) {
    log_->error("{}guide-rope preload: x{} requested by '{}' gives a model the twin refuses ({}): not adopted",
                tag_, r->scale, r->user.data(), e.what());
    busy_.store(false, std::memory_order_release);
    return;
  }
  if (!path_.empty()) {
    try {
      io::writePreloadFile(path_, io::PreloadRecord{r->scale, r->utime, r->user.data()},
                           "the adopted preload's state file");
      log_->info("{}guide-rope preload: x{} by '{}' kept in {} (read at the next start)", tag_, r->scale,
                 r->user.data(), path_);
    } catch (const std::exception& e) {
      log_->error("{}guide-rope preload: x{} by '{}' could not be kept ({}): it is used until the daemon stops",
                  tag_, r->scale, r->user.data(), e.what());
    }
  } else {
    log_->warn("{}guide-rope preload: x{} by '{}' is not kept across a restart (no --state-dir)", tag_, r->scale,
               r->user.data());
  }
  ready_.store(built.release(), std::memory_order_release);
}

void PreloadKeeper::afterTick(TwinCore& core) {
  Built* b = ready_.load(std::memory_order_acquire);
  if (!b) return;
  const Kinematics& k = core.output().kin;
  const double rest = core.config().estimator.settings.rest_speed;
  const bool at_rest = !core.hasOutput() || core.stale() || (std::abs(k.v) <= rest && std::abs(k.a) <= rest);
  if (!at_rest) {
    if (!waiting_logged_)
      rt_log_.info("{}guide-rope preload x{} by '{}' is built and waits for the cage to rest (|v| = {:.2f} m/s)",
                   tag_, b->req.scale, b->req.user.data(), k.v);
    waiting_logged_ = true;
    return;
  }
  ready_.store(nullptr, std::memory_order_release);
  const double from = core.preloadScale();
  try {
    core.adoptModel(b->model);  // built from this shaft's config: same method and n
  } catch (const std::exception&) {
    rt_log_.error("{}guide-rope preload x{} by '{}' does not fit the running twin (another solver or n): not "
                  "adopted", tag_, b->req.scale, b->req.user.data());
    retired_.store(b, std::memory_order_release);
    return;
  }
  adopted_.fetch_add(1, std::memory_order_relaxed);
  rt_log_.warn("{}AUDIT operator '{}': the live twin now runs the guide-rope preloads x{} (Tb1 = {:.0f} N, Tb2 = "
               "{:.0f} N), was x{}, at t = {:.2f} s, l = {:.2f} m; the shaft's memory still judges the shaft against "
               "the config's preloads", tag_, b->req.user.data(), core.preloadScale(), core.config().shaft.Tb1,
               core.config().shaft.Tb2, from, core.publishedTime(core.modelTime()), k.l);
  // The old model goes back to the worker in its shell (freed there, not on
  // the loop); the worker ends the adoption's cycle (busy_) when it has.
  retired_.store(b, std::memory_order_release);
}

}  // namespace hoist::service::app
