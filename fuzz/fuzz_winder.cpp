// libFuzzer target: the daemon's LCM input path -- raw HOIST_WINDER payloads
// through decodeWinder (as hoist-twind's onWinder) into TwinCore::onInput /
// tick / housekeeping.  No input may crash, hang or make an output
// non-finite; every message is either accepted or rejected with a reason.
//
// Input format: a sequence of records [flags][len][len bytes].  flags bit 0:
// prepend winder_t's fingerprint (so the fuzzer reaches the validator
// quickly); bit 1: also tick the wall clock; the first byte's bit 7 selects
// --clock input instead of wall.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "hoist/service/twin/twin_core.hpp"
#include "hoist/service/lcm/winder_decode.hpp"

using namespace hoist::service;

namespace {

bool finiteOutput(const CageOutput& o) {
  bool ok = std::isfinite(o.t) && std::isfinite(o.kin.l) && std::isfinite(o.kin.v) && std::isfinite(o.kin.a) &&
            std::isfinite(o.x_c) && std::isfinite(o.y_c) && std::isfinite(o.theta) &&
            std::isfinite(o.clearance.min_clearance);
  for (double v : o.lambda) ok = ok && std::isfinite(v);
  return ok;
}

TwinConfig config() {
  TwinConfig c;
  c.shaft.n = 4;
  c.service.envelope_points = 11;
  c.service.shape_points = 5;
  c.service.max_step = 0.0;  // one solver step per input: keeps executions fast
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const TwinConfig cfg = config();
  // The shaft model (modes, quadrature) is immutable: build it once.
  static const auto model = std::make_shared<const hoist::ShaftModel>(cfg.shaft);
  const ClockMode clock = (data[0] & 0x80) ? ClockMode::Input : ClockMode::Wall;
  TwinCore core(cfg, clock, hoist::makeSolver(hoist::Method::Fast, model));
  hoist::winder_t scratch{};
  std::int64_t hash = hoist::winder_t::getHash();
  std::uint8_t fp[8];
  for (int i = 0; i < 8; ++i) fp[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(hash) >> (56 - 8 * i));
  std::vector<std::uint8_t> buf;
  std::size_t pos = 1;
  double wall = 0.0;
  std::int64_t handled = 0;
  while (pos + 2 <= size) {
    const std::uint8_t flags = data[pos], len = data[pos + 1];
    pos += 2;
    const std::size_t n = std::min<std::size_t>(len, size - pos);
    buf.clear();
    if (flags & 1) buf.insert(buf.end(), fp, fp + 8);
    buf.insert(buf.end(), data + pos, data + pos + n);
    pos += n;
    wall += 0.001 * (1 + (flags >> 4));
    WinderSample s;
    if (decodeWinder(buf.data(), static_cast<std::int64_t>(buf.size()), scratch, s) != WinderDecode::Ok) {
      core.rejectUndecodable();
    } else {
      const InputResult r = core.onInput(s, wall);
      if (!r.accepted && static_cast<int>(r.reason) >= kRejectReasons) std::abort();
    }
    ++handled;
    if (flags & 2) core.tick(core.modelTime() + 0.01 * (1 + (flags >> 4)), wall);
    core.housekeeping(wall);
    core.clearEvents();
    if (!finiteOutput(core.output())) std::abort();
    const InputCounters& c = core.counters();
    // implausible_state counts model outputs (MODEL_FAULT), not inputs.
    if (c.accepted + c.rejectedTotal() - c.count(RejectReason::Implausible) != handled) std::abort();
  }
  return 0;
}
