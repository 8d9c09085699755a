// hoist/io/preload_file.hpp: the adopted guide-rope preload's file.
#include "hoist/io/preload_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"

namespace hoist::io {

namespace {
constexpr std::size_t kMaxUser = 128;
}

void writePreloadFile(const std::string& path, const PreloadRecord& r, const std::string& label) {
  CheckedFile f(path, label);
  f.printf("# hoist adopted guide-rope preload (hoist-twind's state; written by the daemon, not by hand)\n"
           "preload_scale = %.9g\nadopted_utime = %lld\nadopted_by = %s\n",
           r.preload_scale, static_cast<long long>(r.adopted_utime), r.adopted_by.c_str());
  f.close(true);
}

PreloadRecord readPreloadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open");
  PreloadRecord r;
  bool have_scale = false, have_utime = false, have_user = false;
  std::string line;
  int no = 0;
  while (std::getline(in, line)) {
    ++no;
    if (line.size() > 4096) throw InputError(path, no, "", "line longer than 4096 characters");
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw InputError(path, no, "", "expected 'key = value'");
    std::string key = line.substr(first, eq - first);
    key.erase(key.find_last_not_of(" \t") + 1);
    std::string text = line.substr(eq + 1);
    text.erase(0, text.find_first_not_of(" \t"));
    text.erase(text.find_last_not_of(" \t\r") + 1);
    if (key == "adopted_by") {
      if (have_user) throw InputError(path, no, key, "given twice");
      if (text.size() > kMaxUser) throw InputError(path, no, key, "longer than 128 characters");
      for (const char c : text)
        if (c < 32 || c > 126) throw InputError(path, no, key, "not printable ASCII");
      r.adopted_by = text;
      have_user = true;
      continue;
    }
    char* end = nullptr;
    errno = 0;
    if (key == "preload_scale") {
      if (have_scale) throw InputError(path, no, key, "given twice");
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || !std::isfinite(v)) throw InputError(path, no, key, "not a finite number");
      if (!(v > 0.0 && v <= 10.0)) throw InputError(path, no, key, "must be in (0, 10]");
      r.preload_scale = v;
      have_scale = true;
    } else if (key == "adopted_utime") {
      if (have_utime) throw InputError(path, no, key, "given twice");
      const long long v = std::strtoll(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || errno == ERANGE) throw InputError(path, no, key, "not an integer");
      if (v < 0) throw InputError(path, no, key, "must be >= 0");
      r.adopted_utime = v;
      have_utime = true;
    } else {
      throw InputError(path, no, key, "unknown key (preload_scale, adopted_utime, adopted_by)");
    }
  }
  if (!have_scale) throw InputError(path, 0, "preload_scale", "missing");
  if (!have_utime) throw InputError(path, 0, "adopted_utime", "missing");
  if (!have_user) throw InputError(path, 0, "adopted_by", "missing");
  return r;
}

}  // namespace hoist::io
