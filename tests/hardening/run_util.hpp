// run_util.hpp -- run a program to completion and measure its peak memory
// (for "bounded memory" assertions on hostile files).
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

extern char** environ;

namespace hoist::test {

struct RunResult {
  int status = -1;      ///< exit status, 128 + signal if killed, -1 if not started
  long max_rss_kb = 0;  ///< peak resident set size of the child [KiB]
};

/// Runs argv with stdout+stderr appended to `log_path`; waits for it.
inline RunResult runMeasured(std::vector<std::string> argv, const std::string& log_path) {
  RunResult r;
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return r;
  int st = 0;
  rusage ru{};
  if (wait4(pid, &st, 0, &ru) != pid) return r;
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.max_rss_kb = ru.ru_maxrss;
  return r;
}

}  // namespace hoist::test
