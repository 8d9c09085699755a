// hoist/io/toml_section.hpp -- the one reader of a TOML section with a fixed
// set of keys, used for the shaft sections (driven by hoist::kParamFields)
// and for the daemon's [service] and [alarms].
//
// Every error is a ConfigError "file:line: section.key: reason": a section
// that is not a table, an unknown key (with "did you mean" and the list of
// keys the section takes), a value of the wrong type.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "hoist/io/error.hpp"

namespace hoist::io {

/// 1-based line of a node (0 if unknown).
int lineOf(const toml::node& n);
/// "a string", "an integer", ... for messages.
const char* typeName(const toml::node& n);
/// " (did you mean 'x'?)" or "".
std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates);

class SectionReader {
 public:
  /// `section` may be absent from `root` (then run() does nothing).
  SectionReader(const toml::table& root, std::string section, std::string source);

  using Handler = std::function<void(const toml::node&)>;
  /// Any handler; it reports errors through fail().
  void on(std::string key, Handler h);
  /// A number (integer or float); `finite` rejects inf and nan.
  void number(std::string key, double& out, bool finite = true);
  /// An integer in [lo, hi] (the range is a reading limit, not a validation).
  void integer(std::string key, int& out, long long lo = -1000000000, long long hi = 1000000000);
  void boolean(std::string key, bool& out);
  void string(std::string key, std::function<void(const toml::node&, const std::string&)> set);

  /// Apply the handlers to every key of the section, in file order.
  void run();

  /// Line of `key` in the file, 0 if it was not there.
  int lineOfKey(const std::string& key) const;
  /// Line of the [section] header, 0 if absent.
  int line() const;
  const std::string& section() const { return section_; }
  const std::string& source() const { return source_; }
  /// ConfigError at `n` for "section.key".
  [[noreturn]] void fail(const toml::node& n, const std::string& key, const std::string& why) const;

 private:
  std::string section_;
  std::string source_;
  const toml::table* tbl_ = nullptr;
  std::vector<std::pair<std::string, Handler>> handlers_;  // in registration order
  std::vector<std::pair<std::string, int>> lines_;
};

/// A validate() error of the form "section.key: why" (e.g. ParamError or the
/// daemon's std::invalid_argument) as a ConfigError with the key's line in
/// `source` (the line of the first reader that saw the key; 0 if none did).
[[noreturn]] void rethrowWithLine(const std::string& what, const std::string& source,
                                  const std::vector<const SectionReader*>& readers, bool section_line_fallback);

}  // namespace hoist::io
