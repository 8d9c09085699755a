// hoist/io/accel_offset_file.hpp -- the learned accelerometer offset kept
// across trips and restarts (docs/estimation.md, "The accelerometer's
// offset"): written by hoist-estimate --offset-out and by hoist-twind into its
// state directory, read by hoist-estimate --offset-in and by hoist-twind at
// start.  A tiny text file:
//   # hoist accelerometer offset
//   accel_offset = 0.00979      [m/s^2]
//   sigma = 3.1e-05             [m/s^2]
// Written with io's checked file writer (a temporary file renamed onto the
// target, fsynced: a crash leaves the old file or the new one, never half).
#pragma once

#include <string>

namespace hoist::io {

struct AccelOffsetRecord {
  double offset = 0.0;  ///< [m/s^2]
  double sigma = 0.0;   ///< [m/s^2], >= 0
};

/// Writes `r` to `path` atomically and durably.  `label` (e.g. "--offset-out")
/// prefixes errors.  Throws WriteError.
void writeAccelOffsetFile(const std::string& path, const AccelOffsetRecord& r, const std::string& label = "");

/// Reads a file written by writeAccelOffsetFile.  Throws InputError naming
/// the file, line and key for a missing file, an unknown key, a missing or
/// non-numeric value, |offset| > 1 or a negative sigma.
AccelOffsetRecord readAccelOffsetFile(const std::string& path);

}  // namespace hoist::io
