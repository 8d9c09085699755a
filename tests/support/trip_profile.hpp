// Test support (issue 32): a winder profile CSV (t,v,a at 100 Hz) of rest,
// a trapezoidal trip down `travel` m, rest, the same trip up, rest -- the
// smallest recording with two trips, for hoist-sim --profile.  Used by the
// trip tests of hoist-trips (tests/history) and of the daemon
// (tests/integration/trip_history_daemon_test).
#pragma once

#include <algorithm>
#include <fstream>
#include <string>

namespace hoist::test {

/// Writes the profile to `path`; returns the duration of one trip [s].
inline double writeDownUpProfile(const std::string& path, double rest, double travel, double vmax, double amax) {
  std::ofstream prof(path);
  prof << "t,v,a\n";
  const double dt = 0.01, ta = vmax / amax, tc = (travel - vmax * ta) / vmax, trip = 2 * ta + tc;
  const double total = 3 * rest + 2 * trip;
  for (int i = 0; i * dt <= total + 1e-9; ++i) {
    const double t = i * dt;
    double v = 0.0, a = 0.0, sign = 1.0, u = -1.0;
    if (t > rest && t < rest + trip) u = t - rest;
    else if (t > 2 * rest + trip && t < 2 * rest + 2 * trip) u = t - 2 * rest - trip, sign = -1.0;
    if (u >= 0) {
      if (u < ta) v = amax * u, a = amax;
      else if (u < ta + tc) v = vmax;
      else v = std::max(0.0, vmax - amax * (u - ta - tc)), a = -amax;
    }
    prof << t << "," << sign * v << "," << sign * a << "\n";
  }
  return trip;
}

}  // namespace hoist::test
