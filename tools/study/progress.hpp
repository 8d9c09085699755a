// progress.hpp -- hoist-study's progress line on stderr.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <string>

namespace hoist::study::cli {

/// Progress on stderr when it is a terminal (one line, rewritten).
class Progress {
 public:
  explicit Progress(std::string what) : what_(std::move(what)), tty_(::isatty(STDERR_FILENO) != 0) {}
  void operator()(double f) {
    if (!tty_) return;
    std::lock_guard<std::mutex> lk(m_);
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last_) return;
    last_ = pct;
    std::fprintf(stderr, "\r%s %3d%%", what_.c_str(), pct);
    std::fflush(stderr);
  }
  ~Progress() {
    if (tty_ && last_ >= 0) std::fprintf(stderr, "\r%s done\n", what_.c_str());
  }

 private:
  std::string what_;
  bool tty_;
  int last_ = -1;
  std::mutex m_;
};

}  // namespace hoist::study::cli
