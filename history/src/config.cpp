// [history] (hoist/history/config.hpp).
#include "hoist/history/config.hpp"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "hoist/io/toml_section.hpp"
#include "section.hpp"

namespace hoist::history {

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  throw std::invalid_argument(key + ": " + why);
}

std::string underDir(const std::string& path, const std::string& dir) {
  if (path.empty() || dir.empty() || path.front() == '/') return path;
  return (std::filesystem::path(dir) / path).string();
}

bool hasBlankOnly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char ch = 0;
  for (int n = 0; in.get(ch) && n < 4096; ++n)
    if (!std::isspace(static_cast<unsigned char>(ch))) return false;
  return true;
}

std::string firstLine(const std::string& path, const std::string& key) {
  std::ifstream in(path, std::ios::binary);
  if (!in) bad(key, "cannot read '" + path + "'");
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.empty()) bad(key, "'" + path + "' is empty (its first line is the password)");
  return line;
}

}  // namespace

DatabaseUrl parseDatabaseUrl(const std::string& url, const std::string& key, const std::string& base_dir) {
  if (url.empty()) bad(key, "empty (sqlite:///path, a path, or postgresql://...)");
  for (char c : url)
    if (static_cast<unsigned char>(c) < 0x20) bad(key, "control character in the URL");
  DatabaseUrl u;
  const auto colon = url.find("://");
  const auto scheme = colon == std::string::npos ? std::string() : url.substr(0, colon);
  if (scheme == "postgresql" || scheme == "postgres") {
    const auto rest = url.substr(colon + 3);
    const auto slash = rest.find_first_of("/?");
    const auto authority = rest.substr(0, slash);
    if (const auto at = authority.rfind('@'); at != std::string::npos &&
                                              authority.substr(0, at).find(':') != std::string::npos)
      bad(key, "a password in the URL is refused (it would show in ps, logs and files): "
               "use the credential 'history-password' or history.password_file");
    if (url.find("password=") != std::string::npos)
      bad(key, "a password parameter in the URL is refused: use the credential 'history-password' or "
               "history.password_file");
    u.backend = Backend::Postgres;
    u.target = url;
    return u;
  }
  std::string path;
  if (scheme == "sqlite") {
    path = url.substr(colon + 3);  // sqlite:///abs -> /abs
    if (path.empty() || path.front() != '/')
      bad(key, "'" + url + "': an SQLite URL is sqlite:///absolute/path (three slashes), or give a plain path");
  } else if (!scheme.empty()) {
    bad(key, "unknown scheme '" + scheme + "' (sqlite:///path, a plain path, or postgresql://...)");
  } else if (url.rfind("sqlite:", 0) == 0) {
    path = url.substr(7);
    if (path.empty()) bad(key, "'sqlite:' without a path");
  } else {
    path = url;
  }
  if (path.back() == '/') bad(key, "'" + path + "' is a folder: name the database file");
  u.target = underDir(path, base_dir);
  return u;
}

void HistoryConfig::validate() const {
  if (!url.empty()) (void)parseDatabaseUrl(url, "history.url");
  if (keep_days < 0) bad("history.keep_days", "must be >= 0 (0: keep every trip), got " + std::to_string(keep_days));
  if (keep_days > 36500) bad("history.keep_days", "more than 100 years (" + std::to_string(keep_days) + ")");
  if (!(retry_seconds >= 0.1 && retry_seconds <= 3600.0))
    bad("history.retry_seconds", "must be in [0.1, 3600] s");
  if (!password_file.empty() && !url.empty() && parseDatabaseUrl(url, "history.url").backend != Backend::Postgres)
    bad("history.password_file", "only a postgresql:// database takes a password");
}

HistoryConfig historyConfigFromToml(const toml::table& root, const std::string& source) {
  HistoryConfig c;
  io::SectionReader r(root, "history", source);
  r.string("url", [&c](const toml::node&, const std::string& v) { c.url = v; });
  r.integer("keep_days", c.keep_days, -1000000, 1000000);
  r.string("queue_dir", [&c](const toml::node&, const std::string& v) { c.queue_dir = v; });
  r.string("password_file", [&c](const toml::node&, const std::string& v) { c.password_file = v; });
  r.number("retry_seconds", c.retry_seconds);
  detail::runValidated(r, source, [&c] { c.validate(); });
  return c;
}

StoreOptions resolveStoreOptions(const HistoryConfig& cfg, const std::string& config_dir, const std::string& url_key) {
  cfg.validate();
  StoreOptions o;
  const std::string url = cfg.url.empty() ? underDir("history.sqlite", config_dir.empty() ? "." : config_dir) : cfg.url;
  o.db = parseDatabaseUrl(url, url_key, config_dir);
  o.retry_seconds = cfg.retry_seconds;
  o.queue_dir = cfg.queue_dir.empty() ? underDir("history-queue", config_dir.empty() ? "." : config_dir)
                                      : underDir(cfg.queue_dir, config_dir);
  if (o.db.backend != Backend::Postgres) return o;
  if (const char* dir = std::getenv("CREDENTIALS_DIRECTORY"); dir && *dir) {
    const std::string cred = std::string(dir) + "/" + kPasswordCredential;
    // Blank: the unit's SetCredential= default, i.e. no credential.
    if (std::filesystem::exists(cred) && !hasBlankOnly(cred)) {
      o.password = firstLine(cred, std::string("credential ") + kPasswordCredential);
      return o;
    }
  }
  if (!cfg.password_file.empty())
    o.password = firstLine(underDir(cfg.password_file, config_dir), "history.password_file");
  return o;
}

}  // namespace hoist::history
