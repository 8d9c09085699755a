// Uses each exported target of find_package(hoist) once: a shaft from TOML
// (hoist::io), its static equilibrium (hoist::model), and the result as an
// LCM message (hoist::msgs), encoded and decoded, on its channel's name
// (hoist::lcm's generated hoist/bus/channels.hpp).  The decode check also
// catches LCM 1.3.1's strict-aliasing bug (lcm_coretypes.h writes doubles
// through int64_t*: at -O2 GCC drops them) if hoist::msgs stopped carrying
// -fno-strict-aliasing to its users.
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <hoist/bus/channels.hpp>
#include <hoist/cage_state_t.hpp>
#include <hoist/fast_solver.hpp>
#include <hoist/io/config.hpp>
#include <hoist/shaft_model.hpp>

int main() {
  const hoist::ShaftParams p =
      hoist::io::shaftParamsFromToml(hoist::io::parseToml("[cage]\nmass = 800.0\n[model]\nmodes = 20\n"), "consumer");
  auto model = std::make_shared<const hoist::ShaftModel>(p);
  hoist::FastSolver solver(model);
  solver.initialize(0.0, hoist::Kinematics{p.l0, 0.0, 0.0}, hoist::InitialState::Static);
  const hoist::CageResponse& r = solver.response();

  hoist::cage_state_t m{};
  m.t = r.t;
  m.l = r.kin.l;
  m.y_c = r.y_c;
  m.theta = r.theta;
  for (int k = 0; k < 5; ++k) m.lambdas[k] = r.lambda[k];
  std::vector<unsigned char> buf(static_cast<std::size_t>(m.getEncodedSize()));
  hoist::cage_state_t back{};
  const int encoded = m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const int decoded = back.decode(buf.data(), 0, static_cast<int>(buf.size()));
  const bool ok = encoded == static_cast<int>(buf.size()) && decoded == encoded && back.y_c == r.y_c &&
                  back.lambdas[1] == r.lambda[1] && std::isfinite(r.y_c) && r.y_c > 0.004 && r.y_c < 0.006;
  const hoist::bus::Channels ch("north/");
  const bool named = ch.cage == "north/HOIST_CAGE" && hoist::bus::kChannelCage == "HOIST_CAGE";
  std::printf("hoist-consumer: n=%d l=%.1f m static y_c=%.4f mm, cage_state_t %zu bytes on %s: %s\n", p.n, m.l,
              r.y_c * 1e3, buf.size(), ch.cage.c_str(), ok && named ? "ok" : "FAIL");
  return ok && named ? 0 : 1;
}
