// hoist/io/profile.hpp -- hoist profiles from CSV files and SPEC strings.
//
// CSV (docs/model.md): a header row naming the columns; `t` [s], `v` [m/s] and
// `a` [m/s^2] required, `l` [m] optional (absent: l is integrated from v
// starting at l0).  Other columns are ignored, so a hoist-sim result file is
// also a valid profile.  Lines starting with '#' and blank lines are skipped;
// a UTF-8 byte-order mark and CRLF line ends are accepted.  Rejected with the
// line number: missing/duplicate columns, non-numeric or non-finite fields,
// wrong field counts, t not strictly increasing, a gap between samples longer
// than ProfileLimits::max_gap, |v| or |a| beyond the limits, l <= 0, fewer than
// two samples, an empty or binary file.
//
// SPEC: a synthetic profile, `NAME[:key=value,...]`:
//   paper                          the paper's Fig. 2 trapezoid (l0 -> l0 + 250 m, 60 s)
//   trapezoid:vmax=5,amax=1,travel=250,t_end=60,dt=0.01,l0=<initial_length>
//   scurve:vmax=5,amax=1,jmax=0.5,travel=250,t_end=70,dt=0.01,l0=...
//   estop:vmax=5,t_stop=20,decel=3,t_end=30,dt=0.01,l0=...
//   rest:t_end=60,dt=0.01,l0=...   (the cage held still)
// `travel` < 0 hoists (l decreases); `vmax` < 0 in estop likewise.
#pragma once

#include <iosfwd>
#include <string>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"
#include "hoist/params.hpp"
#include "hoist/profile.hpp"

namespace hoist::io {

struct ProfileLimits {
  double max_gap = 10.0;     ///< largest time between two samples [s]
  double max_speed = 50.0;   ///< |v| [m/s]
  double max_accel = 50.0;   ///< |a| [m/s^2]
  std::size_t max_rows = 20'000'000;  ///< guards memory
};

/// Read a profile CSV from a stream; `source` names it in messages.
HoistProfile readProfileCsv(std::istream& in, const std::string& source, double l0,
                            const ProfileLimits& limits = {});
HoistProfile readProfileCsvFile(const std::string& path, double l0, const ProfileLimits& limits = {});

/// Build a synthetic profile from a SPEC (see above).  Throws ProfileError.
HoistProfile profileFromSpec(const std::string& spec, double l0);

/// True when `arg` has the shape of a SPEC (a known name, optionally ':...').
bool isProfileSpec(const std::string& arg);

/// An existing file is read as CSV; otherwise `arg` must be a SPEC.
HoistProfile loadProfile(const std::string& arg, double l0, const ProfileLimits& limits = {});

/// Throws ProfileError naming the first time at which l leaves the shaft,
/// 0 < l < L - 2h (the bottom sleeves must stay on the guide ropes).
void checkProfileInShaft(const HoistProfile& profile, const ShaftParams& p, const std::string& source);

/// Write `t,l,v,a` rows (shortest round-trip doubles).
void writeProfileCsv(std::ostream& out, const HoistProfile& profile);
/// The same, every byte checked (throws WriteError naming the file).
void writeProfileCsv(CheckedFile& out, const HoistProfile& profile);

/// One paragraph describing the SPEC syntax, for --help texts.
const char* profileSpecHelp();

}  // namespace hoist::io
