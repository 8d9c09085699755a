// hoist/io/preload_file.hpp: the adopted guide-rope preload's file.
#include "hoist/io/preload_file.hpp"

#include <cerrno>
#include <cstdlib>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"
#include "hoist/io/key_value_file.hpp"

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
  PreloadRecord r;
  bool have_scale = false, have_utime = false, have_user = false;
  readKeyValueFile(path, [&](int no, const std::string& key, const std::string& text) {
    if (key == "preload_scale") {
      const double v = finiteValue(path, no, key, text);
      if (!(v > 0.0 && v <= 10.0)) throw InputError(path, no, key, "must be in (0, 10]");
      r.preload_scale = v;
      have_scale = true;
    } else if (key == "adopted_utime") {
      char* end = nullptr;
      errno = 0;
      const long long v = std::strtoll(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || errno == ERANGE) throw InputError(path, no, key, "not an integer");
      if (v < 0) throw InputError(path, no, key, "must be >= 0");
      r.adopted_utime = v;
      have_utime = true;
    } else if (key == "adopted_by") {
      if (text.size() > kMaxUser) throw InputError(path, no, key, "longer than 128 characters");
      for (const char c : text)
        if (c < 32 || c > 126) throw InputError(path, no, key, "not printable ASCII");
      r.adopted_by = text;
      have_user = true;
    } else {
      throw InputError(path, no, key, "unknown key (preload_scale, adopted_utime, adopted_by)");
    }
  });
  if (!have_scale) throw InputError(path, 0, "preload_scale", "missing");
  if (!have_utime) throw InputError(path, 0, "adopted_utime", "missing");
  if (!have_user) throw InputError(path, 0, "adopted_by", "missing");
  return r;
}

}  // namespace hoist::io
