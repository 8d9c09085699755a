// hoist/io/error.hpp -- the one error type of hoist_io.
//
// Every message has the form `SOURCE[:LINE]: KEY: what is wrong`, where
// SOURCE is the file name (or "<spec>" / "<string>"), LINE the 1-based line
// when known, and KEY the TOML key ("cage.mass"), the CSV column ("v") or the
// spec parameter ("trapezoid.vmax").  Tools print what() and exit with status 2.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace hoist::io {

class InputError : public std::runtime_error {
 public:
  InputError(std::string source, int line, std::string key, const std::string& message);
  const std::string& source() const { return source_; }
  int line() const { return line_; }  ///< 0 when unknown
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }

 private:
  std::string source_;
  int line_;
  std::string key_;
  std::string message_;
};

/// Errors in a TOML configuration.
class ConfigError : public InputError {
 public:
  using InputError::InputError;
};

/// Errors in a profile CSV or SPEC.
class ProfileError : public InputError {
 public:
  using InputError::InputError;
};

/// The closest candidate to `word` by edit distance, or "" if none is close
/// enough to be a plausible misspelling (used for "did you mean ...?").
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace hoist::io
