// hoist/io/preload_file.hpp -- the guide-rope preload an operator adopted
// into the live twin (alarm_ack_t ACTION_ADOPT_PRELOAD; docs/condition.md
// "Adopting the identified preload"), kept across restarts in hoist-twind's
// state directory; never in the config file.  A tiny text file:
//   # hoist adopted guide-rope preload
//   preload_scale = 0.82
//   adopted_utime = 1765100000000000   [us since the Unix epoch]
//   adopted_by = alice
// Written with io's checked file writer (a temporary file renamed onto the
// target, fsynced: a crash leaves the old file or the new one, never half).
#pragma once

#include <cstdint>
#include <string>

namespace hoist::io {

struct PreloadRecord {
  double preload_scale = 1.0;   ///< both guide-rope preloads times this
  std::int64_t adopted_utime = 0;  ///< when the operator adopted it [us since the epoch]
  std::string adopted_by;       ///< who (printable ASCII, at most 128 characters)
};

/// Writes `r` to `path` atomically and durably.  Throws WriteError.
void writePreloadFile(const std::string& path, const PreloadRecord& r, const std::string& label = "");

/// Reads a file written by writePreloadFile.  Throws InputError naming the
/// file, line and key for a missing file, an unknown or repeated key, a
/// missing value, a scale that is not a finite number in (0, 10], a negative
/// utime, or a user longer than 128 characters or outside printable ASCII.
PreloadRecord readPreloadFile(const std::string& path);

}  // namespace hoist::io
