// hoist/dash static_files.hpp -- the page's files, read once at start-up from
// the web root into memory.  A request can only ever get one of these files:
// its path is percent-decoded, checked for traversal ("..", backslashes, NUL,
// encoded variants) and then looked up by exact name; nothing is opened from
// the file system after start-up.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <string_view>

namespace hoist::dash {

struct StaticFile {
  std::string body;
  std::string content_type;
};

class StaticFiles {
 public:
  /// Loads every regular file under `root` (two levels deep, at most 8 MiB
  /// each).  Throws std::runtime_error naming the root when it has no index.html.
  explicit StaticFiles(const std::string& root);
  StaticFiles() = default;

  enum class Verdict { Found, NotFound, BadRequest, Traversal };
  /// Classifies a request target ("/app.js?x=1") and finds its file.
  Verdict lookup(std::string_view target, const StaticFile** file) const;
  std::size_t size() const { return files_.size(); }
  void add(const std::string& path, std::string body, std::string type) { files_[path] = {std::move(body), std::move(type)}; }

 private:
  std::map<std::string, StaticFile> files_;  // "/index.html" -> file
};

/// Percent-decodes `in` into `out`; false on a malformed escape.
bool percentDecode(std::string_view in, std::string& out);
std::string contentTypeOf(const std::string& path);

}  // namespace hoist::dash
