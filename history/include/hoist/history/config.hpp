// hoist/history/config.hpp -- [history]: where the trip records go.
//
//   [history]
//   url = "sqlite:///var/lib/hoist-twin/history.sqlite"  # or a plain path, or postgresql://...
//   keep_days = 0            # retention: trips older than this are pruned (0: keep all)
//   queue_dir = ""           # PostgreSQL outage queue ("": beside the configuration, history-queue/)
//   password_file = ""       # PostgreSQL password (first line); a systemd credential wins
//   retry_seconds = 10       # PostgreSQL: least time between reconnection attempts while down
//
// The URL: `sqlite:///abs/path`, `sqlite:rel/path`, a plain path (SQLite),
// or `postgresql://[user@]host[:port]/db[?param=...]` (also `postgres://`;
// libpq's URI, e.g. `postgresql://hoist@/twin?host=/run/postgresql`).  A
// password in the URL is refused: it would show in `ps`, logs and the
// config file.  The password comes from $CREDENTIALS_DIRECTORY/history-password
// (systemd LoadCredential=history-password:/etc/hoist-twin/history-password,
// as hoist-mqtt's mqtt-password), else `password_file`, else libpq's own
// ~/.pgpass / PGPASSFILE.
//
// Errors: io::ConfigError "file:line: history.key: why" from the reader,
// "history.key: why" (std::invalid_argument) from validate().
#pragma once

#include <string>

#include <toml++/toml.h>

namespace hoist::history {

enum class Backend { Sqlite, Postgres };

struct DatabaseUrl {
  Backend backend = Backend::Sqlite;
  std::string target;  ///< the SQLite file, or libpq's connection URI
};

/// Parses `url` (see above).  Throws std::invalid_argument "KEY: why" where
/// KEY is `key` (e.g. "history.url" or "--db").  A relative SQLite path is
/// taken relative to `base_dir` when that is not empty.
DatabaseUrl parseDatabaseUrl(const std::string& url, const std::string& key, const std::string& base_dir = "");

struct HistoryConfig {
  std::string url;            ///< "" = `history.sqlite` beside the configuration
  int keep_days = 0;          ///< 0: keep every trip
  std::string queue_dir;      ///< "" = `history-queue` beside the configuration
  std::string password_file;  ///< PostgreSQL only
  double retry_seconds = 10.0;

  /// Throws std::invalid_argument "history.key: why".
  void validate() const;
};

/// [history] of a parsed file (absent: the defaults).  Unknown keys, wrong
/// types and what validate() refuses: io::ConfigError with file and line.
HistoryConfig historyConfigFromToml(const toml::table& root, const std::string& source);

/// The settings a store opens with: the URL parsed, relative paths and the
/// defaults resolved against `config_dir` (the configuration file's folder;
/// "" = the working directory), the password read (never logged).
struct StoreOptions {
  DatabaseUrl db;
  std::string queue_dir;
  std::string password;  ///< "" = none (libpq may still use ~/.pgpass)
  double retry_seconds = 10.0;
  bool read_only = false;  ///< SQLite: never create or migrate; a missing file is an error
};

/// Resolves `cfg` (validated) into StoreOptions; `url_key` names the URL's
/// origin in messages ("history.url", "--db").  Reads the password from the
/// credential or password_file (std::invalid_argument naming
/// history.password_file when unreadable or empty).
StoreOptions resolveStoreOptions(const HistoryConfig& cfg, const std::string& config_dir,
                                 const std::string& url_key = "history.url");

/// The systemd credential's name: $CREDENTIALS_DIRECTORY/history-password.
inline constexpr const char* kPasswordCredential = "history-password";

}  // namespace hoist::history
