#include "static_files.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace hoist::dash {

namespace fs = std::filesystem;

bool percentDecode(std::string_view in, std::string& out) {
  out.clear();
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != '%') {
      out.push_back(in[i]);
      continue;
    }
    if (i + 2 >= in.size()) return false;
    const int a = hex(in[i + 1]), b = hex(in[i + 2]);
    if (a < 0 || b < 0) return false;
    out.push_back(static_cast<char>(a * 16 + b));
    i += 2;
  }
  return true;
}

std::string contentTypeOf(const std::string& path) {
  auto ends = [&](const char* s) {
    const std::string e(s);
    return path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".png")) return "image/png";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".json")) return "application/json";
  return "application/octet-stream";
}

StaticFiles::StaticFiles(const std::string& root) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::path(root) / "index.html", ec))
    throw std::runtime_error("web root " + root + " has no index.html (use --web-root DIR)");
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it.depth() > 1) {
      it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file(ec) || it->file_size(ec) > (8u << 20)) continue;
    const std::string rel = "/" + fs::relative(it->path(), root, ec).generic_string();
    std::ifstream f(it->path(), std::ios::binary);
    std::ostringstream ss;
    ss << f.rdbuf();
    files_[rel] = {ss.str(), contentTypeOf(rel)};
  }
}

StaticFiles::Verdict StaticFiles::lookup(std::string_view target, const StaticFile** file) const {
  *file = nullptr;
  if (target.empty() || target.front() != '/' || target.size() > 1024) return Verdict::BadRequest;
  const auto q = target.find_first_of("?#");
  const std::string_view path = target.substr(0, q);
  std::string dec;
  if (!percentDecode(path, dec)) return Verdict::BadRequest;
  // Decode twice: "%252e%252e" must not slip through a later decoder either.
  std::string dec2;
  if (!percentDecode(dec, dec2)) dec2 = dec;
  for (const std::string* s : {&dec, &dec2}) {
    if (s->find('\0') != std::string::npos || s->find('\\') != std::string::npos) return Verdict::Traversal;
    // Any ".." path segment (also at the start or end).
    const std::string p = "/" + *s + "/";
    if (p.find("/../") != std::string::npos || p.find("/..\\") != std::string::npos) return Verdict::Traversal;
  }
  std::string key = dec == "/" ? "/index.html" : dec;
  const auto it = files_.find(key);
  if (it == files_.end()) return Verdict::NotFound;
  *file = &it->second;
  return Verdict::Found;
}

}  // namespace hoist::dash
