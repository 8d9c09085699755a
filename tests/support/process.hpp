// tests/support/process.hpp -- running the project's programs from tests:
// a child process with a timeout and its output in a log file or on a given
// descriptor (Process, runProcess), a program run to completion with its
// peak memory (runMeasured) or its output captured (runCaptured), and small
// file helpers.  The one spawn/wait implementation of the tests.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hoist::test {

/// VmRSS of a running process [KiB] (/proc/PID/status), 0 if unknown.
inline long vmRssKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

using namespace std::chrono_literals;

/// A child process; killed (SIGKILL) if still running when destroyed.
class Process {
 public:
  /// stdout and stderr appended to `log_path`, stdin from /dev/null.
  Process(std::vector<std::string> argv, const std::string& log_path) : argv_(std::move(argv)) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
    spawn(fa);
  }
  /// stdout and stderr onto the descriptor `output_fd` (e.g. a pipe's write
  /// end; the caller keeps and closes its own copy), stdin from /dev/null.
  Process(std::vector<std::string> argv, int output_fd) : argv_(std::move(argv)) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, output_fd, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&fa, output_fd, STDERR_FILENO);
    spawn(fa);
  }
  ~Process() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      int st;
      ::waitpid(pid_, &st, 0);
    }
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  bool running() {
    if (pid_ <= 0 || done_) return false;
    int st;
    rusage ru{};
    const pid_t r = ::wait4(pid_, &st, WNOHANG, &ru);
    if (r == pid_) {
      done_ = true;
      status_ = st;
      max_rss_kb_ = ru.ru_maxrss;
      return false;
    }
    return true;
  }
  void signal(int sig) {
    if (running()) ::kill(pid_, sig);
  }
  /// Exit status (0..255, 128+signal if killed), or -1 on timeout.
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (running()) {
      if (std::chrono::steady_clock::now() > end) return -1;
      std::this_thread::sleep_for(5ms);
    }
    if (pid_ <= 0) return -1;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }
  /// Peak resident set size of the finished child [KiB] (0 while it runs).
  long maxRssKb() const { return max_rss_kb_; }

 private:
  void spawn(posix_spawn_file_actions_t& fa) {
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    std::vector<char*> args;
    for (auto& a : argv_) args.push_back(a.data());
    args.push_back(nullptr);
    if (posix_spawn(&pid_, args[0], &fa, nullptr, args.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }

  std::vector<std::string> argv_;
  pid_t pid_ = -1;
  bool done_ = false;
  int status_ = 0;
  long max_rss_kb_ = 0;
};

/// Run to completion (with timeout); returns the exit status or -1.
inline int runProcess(std::vector<std::string> argv, const std::string& log_path,
                      std::chrono::milliseconds timeout) {
  Process p(std::move(argv), log_path);
  if (!p.started()) return -1;
  return p.wait(timeout);
}

struct RunResult {
  int status = -1;      ///< exit status, 128 + signal if killed, -1 if not started or timed out
  long max_rss_kb = 0;  ///< peak resident set size of the child [KiB]
};

/// Runs argv to completion (at most `timeout`) with stdout+stderr appended
/// to `log_path`; its exit status and peak memory (for "bounded memory"
/// assertions on hostile input).
inline RunResult runMeasured(std::vector<std::string> argv, const std::string& log_path,
                             std::chrono::milliseconds timeout = std::chrono::minutes(2)) {
  Process p(std::move(argv), log_path);
  RunResult r;
  if (!p.started()) return r;
  r.status = p.wait(timeout);
  r.max_rss_kb = p.maxRssKb();
  return r;
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The output (stdout and stderr) and exit status of a program run to completion.
struct CapturedRun {
  int status = -1;  ///< exit status, -1 if it did not exit normally
  std::string output;
};

/// `s` quoted for /bin/sh.
inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''";
    else q.push_back(c);
  }
  return q + "'";
}

/// Run `exe args...` through the shell with stdin from /dev/null; capture
/// stdout and stderr together.
inline CapturedRun runCaptured(const std::string& exe, const std::vector<std::string>& args) {
  std::string cmd = shellQuote(exe);
  for (const auto& a : args) cmd += " " + shellQuote(a);
  cmd += " 2>&1 </dev/null";
  CapturedRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// A full disk for the files a program writes: runCaptured with the file size
/// limited to `kib` KiB (RLIMIT_FSIZE; SIGXFSZ ignored), so a write past it
/// fails with EFBIG ("File too large").  The programs refuse to write to
/// /dev/full (a device node, not a file of theirs: hoist/io/checked_file.hpp),
/// which the full-disk tests used before.  The null device is not limited.
inline CapturedRun runCapturedWithFileSizeLimit(const std::string& exe, const std::vector<std::string>& args,
                                                long kib) {
  std::vector<std::string> a = {"-c", "trap '' XFSZ; ulimit -f " + std::to_string(kib * 2) + " && exec \"$0\" \"$@\"",
                                exe};
  a.insert(a.end(), args.begin(), args.end());
  return runCaptured("/bin/sh", a);
}

#ifdef HOIST_TEST_WORK_DIR
/// A fresh directory for one test's files.
inline std::filesystem::path testDir(const std::string& name) {
  const auto dir = std::filesystem::path(HOIST_TEST_WORK_DIR) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}
#endif

}  // namespace hoist::test
