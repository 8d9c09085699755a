// The bridge's LCM side: see lcm_side.hpp.
#include "lcm_side.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "hoist/mqtt/command.hpp"

namespace hoist::mqtt {

LcmSide::LcmSide(const std::string& url, LogBudget& log) : url_(url), lcm_(url), log_(log) {
  if (!lcm_.good())
    throw std::runtime_error("cannot open LCM (" + hoist::bus::describeLcmUrl(url_) +
                             "); is loopback multicast enabled? (scripts/setup.sh)");
}

void LcmSide::listen(Resolve resolve) {
  resolve_ = std::move(resolve);
  std::string why;
  if (!rx_.open(url_, why)) throw std::runtime_error(why);
  // One subscription for every shaft; as LCM's regular expression (anchored):
  // ".*(HOIST_CAGE|HOIST_HEALTH|...)".
  std::string regex = ".*(";
  for (std::size_t i = 0; i < routes_.size(); ++i) regex += (i ? "|" : "") + routes_[i].suffix;
  regex += ")";
  rx_.addMatching(
      [this](std::string_view n) {
        for (const auto& r : routes_)
          if (n.size() >= r.suffix.size() && n.substr(n.size() - r.suffix.size()) == r.suffix) return true;
        return false;
      },
      regex, [this](const lcm::ReceiveBuffer* rb, const std::string& channel) { onMessage(rb, channel); });
}

void LcmSide::onMessage(const lcm::ReceiveBuffer* rb, const std::string& channel) {
  try {
    ++messages_;
    for (const auto& r : routes_) {
      if (channel.size() < r.suffix.size() ||
          std::string_view(channel).substr(channel.size() - r.suffix.size()) != r.suffix)
        continue;
      const Shaft* s = resolve_(channel.substr(0, channel.size() - r.suffix.size()));
      if (!s) return void(++ignored_);
      return r.run(*s, rb, channel);
    }
  } catch (const std::exception& e) {  // nothing may escape an LCM callback
    ++decode_errors_["exception"];
    spdlog::error("error handling {}: {}", printable(channel), e.what());
  } catch (...) {
    ++decode_errors_["exception"];
  }
}

void LcmSide::decodeError(const char* type, hoist::msg::DecodeStatus st, const std::string& channel) {
  ++decode_errors_[std::string(type) + "/" + hoist::msg::toString(st)];
  std::int64_t suppressed = 0;
  if (log_.allow(LogBudget::kLcm, Clock::now(), suppressed))
    spdlog::warn("undecodable {} on {} ({}){}", type, printable(channel), hoist::msg::toString(st),
                 suppressed ? fmt::format(" ({} similar lines suppressed)", suppressed) : "");
}

std::uint64_t LcmSide::decodeErrorsTotal() const {
  std::uint64_t n = 0;
  for (const auto& [k, v] : decode_errors_) n += v;
  return n;
}

}  // namespace hoist::mqtt
