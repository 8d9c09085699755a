// hoist/io/key_value_file.hpp -- the daemon's small state files
// (accel_offset_file.hpp, preload_file.hpp): lines "key = value", '#'
// comments and blank lines.  One reader of the format, so that every state
// file refuses the same damage with the same words.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace hoist::io {

/// The largest state file read [bytes].
inline constexpr std::uintmax_t kMaxKeyValueFileBytes = 64 * 1024;

/// Calls `take(line_number, key, value)` for each "key = value" line of
/// `path` (key and value trimmed of blanks; a value may be empty), in order.
/// Throws InputError naming the file and line for a file that cannot be
/// opened, a file over kMaxKeyValueFileBytes (checked before reading), a line without '=', a line longer than 4096 characters or a key
/// given twice; `take` throws InputError for a key or value it refuses.
void readKeyValueFile(const std::string& path,
                      const std::function<void(int line, const std::string& key, const std::string& value)>& take);

/// `value` as a finite double, or InputError(path, line, key, "not a finite number").
double finiteValue(const std::string& path, int line, const std::string& key, const std::string& value);

}  // namespace hoist::io
