// The daemon's small state files: see hoist/io/key_value_file.hpp.
#include "hoist/io/key_value_file.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "hoist/io/error.hpp"

namespace hoist::io {

namespace {
std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}
}  // namespace

void readKeyValueFile(const std::string& path,
                      const std::function<void(int line, const std::string& key, const std::string& value)>& take) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open");
  // A state file is a few lines: its size is checked before a line is read
  // (getline would grow a string over a file without newlines).
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxKeyValueFileBytes)
    throw InputError(path, 0, "", "larger than " + std::to_string(kMaxKeyValueFileBytes / 1024) + " KiB: not a state file");
  std::set<std::string> seen;
  std::string line;
  int no = 0;
  while (std::getline(in, line)) {
    ++no;
    if (line.size() > 4096) throw InputError(path, no, "", "line longer than 4096 characters");
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '#') continue;
    const auto eq = t.find('=');
    if (eq == std::string::npos) throw InputError(path, no, "", "expected 'key = value'");
    const std::string key = trimmed(t.substr(0, eq));
    if (!seen.insert(key).second) throw InputError(path, no, key, "given twice");
    take(no, key, trimmed(t.substr(eq + 1)));
  }
}

double finiteValue(const std::string& path, int line, const std::string& key, const std::string& value) {
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(v)) throw InputError(path, line, key, "not a finite number");
  return v;
}

}  // namespace hoist::io
