// pg_server.hpp -- a real PostgreSQL server for one test, from Debian's
// package (/usr/lib/postgresql/<v>/bin), as an ordinary user: as root the
// server's programs run as `postgres` through runuser.  Its data, log and
// unix socket live in a fresh /tmp/hoist-pg-XXXXXX (no TCP listener), the
// superuser `postgres` has a password (scram-sha-256), so the client's
// credential path is exercised.  The destructor stops the server and removes
// the folder on every exit path of the test (a failed assertion too); for
// the paths a destructor does not see (a crash, ctest's timeout kill) the
// folder is also listed in HOIST_TEST_WORK_DIR/pg-servers/, and the CTest
// fixture cleanup `history_pg_cleanup` (pg_cleanup.cmake) stops and removes
// whatever is listed there after the postgres tests.
#pragma once

#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "process.hpp"

namespace hoist::test {

class PgServer {
 public:
  /// The folder of initdb/pg_ctl/postgres, or "" when PostgreSQL is not installed.
  static std::string binDir() {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::string best;
    for (const auto& d : fs::directory_iterator("/usr/lib/postgresql", ec))
      if (fs::exists(d.path() / "bin" / "pg_ctl") && d.path().string() > best) best = d.path().string();
    return best.empty() ? "" : best + "/bin";
  }

  PgServer(int port, std::string password) : port_(port), password_(std::move(password)), bin_(binDir()) {
    char tmpl[] = "/tmp/hoist-pg-XXXXXX";
    if (!::mkdtemp(tmpl)) return;
    dir_ = tmpl;
    ::chmod(dir_.c_str(), 0755);
    std::filesystem::create_directories(std::string(HOIST_TEST_WORK_DIR) + "/pg-servers");
    listing_ = std::string(HOIST_TEST_WORK_DIR) + "/pg-servers/" + dir_.substr(5);  // hoist-pg-XXXXXX
    { std::ofstream(listing_) << dir_ << "\n"; }
    if (::geteuid() == 0) {
      const passwd* pw = ::getpwnam("postgres");
      if (!pw) return;
      if (::chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) return;
      as_ = "runuser -u postgres -- ";
    }
    { std::ofstream(dir_ + "/pwfile") << password_ << "\n"; }
    if (!as_.empty()) {
      const passwd* pw = ::getpwnam("postgres");
      if (::chown((dir_ + "/pwfile").c_str(), pw->pw_uid, pw->pw_gid) != 0) return;
    }
    ok_ = sh(as_ + shellQuote(bin_ + "/initdb") + " -D " + shellQuote(dir_ + "/data") +
             " -U postgres -A scram-sha-256 --pwfile=" + shellQuote(dir_ + "/pwfile") + " -E UTF8 --no-sync") == 0 &&
          start();
  }
  ~PgServer() {
    stop();
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
    if (!listing_.empty()) std::filesystem::remove(listing_);
  }
  PgServer(const PgServer&) = delete;
  PgServer& operator=(const PgServer&) = delete;

  bool ok() const { return ok_; }
  bool start() {
    running_ = sh(as_ + shellQuote(bin_ + "/pg_ctl") + " -D " + shellQuote(dir_ + "/data") + " -l " +
                  shellQuote(dir_ + "/log") + " -w -t 60 -o " +
                  shellQuote("-k " + dir_ + " -p " + std::to_string(port_) + " -c listen_addresses=") + " start") == 0;
    return running_;
  }
  bool stop() {
    if (!running_) return true;
    running_ = sh(as_ + shellQuote(bin_ + "/pg_ctl") + " -D " + shellQuote(dir_ + "/data") + " -m fast -w -t 60 stop") != 0;
    return !running_;
  }
  /// The URL of the superuser's database (no password in it).
  std::string url() const {
    return "postgresql://postgres@/postgres?host=" + dir_ + "&port=" + std::to_string(port_);
  }
  /// psql -c `sql` as the superuser; its output (unaligned, tuples only).
  CapturedRun psql(const std::string& sql) const {
    return runCaptured("/usr/bin/env", {"PGPASSWORD=" + password_, "psql", "-X", "-q", "-A", "-t", "-v", "ON_ERROR_STOP=1",
                                        "-h", dir_, "-p", std::to_string(port_), "-U", "postgres", "-d", "postgres",
                                        "-c", sql});
  }
  const std::string& dir() const { return dir_; }
  std::string log() const { return readFile(dir_ + "/log"); }

 private:
  static int sh(const std::string& cmd) {
    const int st = std::system((cmd + " >/dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }
  int port_;
  std::string password_, bin_, dir_, as_, listing_;
  bool ok_ = false, running_ = false;
};

}  // namespace hoist::test
