// libFuzzer target: the shaft/daemon configuration loader.
//   hoist::io::parseToml + shaftParamsFromToml (+ the daemon's [service] and
//   [alarms] sections).  Every input must either load or throw a
//   std::exception with a non-empty message; a loaded configuration must
//   survive a toToml round trip unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "hoist/io/config.hpp"
#include "hoist/service/cfg/config_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  toml::table tbl;
  try {
    tbl = hoist::io::parseToml(text, "fuzz.toml");
  } catch (const std::exception& e) {
    if (!*e.what()) std::abort();
    return 0;
  }
  hoist::ShaftParams p;
  try {
    p = hoist::io::shaftParamsFromToml(tbl, "fuzz.toml", {"service", "alarms", "forecast"});
  } catch (const std::exception& e) {
    if (!*e.what()) std::abort();
    return 0;
  }
  // Round trip: what we print we must read back identically.
  const hoist::ShaftParams q = hoist::io::shaftParamsFromToml(hoist::io::parseToml(hoist::io::toToml(p), "rt"), "rt");
  if (!(q == p))  // every field of hoist::kParamFields (ShaftParams::operator== is member-wise)
    std::abort();
  try {
    hoist::service::TwinConfig cfg;
    cfg.shaft = p;
    hoist::service::parseServiceSections(tbl, "fuzz.toml", cfg);
    (void)hoist::service::toToml(cfg);
  } catch (const std::exception& e) {
    if (!*e.what()) std::abort();
  }
  return 0;
}
