// tests/support/process.hpp -- running the project's programs from tests:
// a child process with a timeout and its output in a log file (Process,
// runProcess), a program run to completion with its output captured
// (runCaptured), and small file helpers.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
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

using namespace std::chrono_literals;

/// A child process; killed (SIGKILL) if still running when destroyed.
class Process {
 public:
  Process(std::vector<std::string> argv, const std::string& log_path) : argv_(std::move(argv)) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    std::vector<char*> args;
    for (auto& a : argv_) args.push_back(a.data());
    args.push_back(nullptr);
    if (posix_spawn(&pid_, args[0], &fa, nullptr, args.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
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
  bool running() {
    if (pid_ <= 0 || done_) return false;
    int st;
    const pid_t r = ::waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      done_ = true;
      status_ = st;
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

 private:
  std::vector<std::string> argv_;
  pid_t pid_ = -1;
  bool done_ = false;
  int status_ = 0;
};

/// Run to completion (with timeout); returns the exit status or -1.
inline int runProcess(std::vector<std::string> argv, const std::string& log_path,
                      std::chrono::milliseconds timeout) {
  Process p(std::move(argv), log_path);
  if (!p.started()) return -1;
  return p.wait(timeout);
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
