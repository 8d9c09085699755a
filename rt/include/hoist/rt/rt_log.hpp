// RtLog: logging from the real-time thread without allocation, I/O or a lock
// that can block.
//
//   producer (the io_context thread, one only): log() formats the line into a
//     fixed-size slot of a preallocated single-producer/single-consumer ring
//     (fmt::format_to_n into a char array: no heap) and publishes it with one
//     release store; wait-free.  A full ring drops the line and counts it
//     (dropped()); a line longer than kText is truncated, never grown.
//   consumer (a background thread started here): every 20 ms moves the queued
//     lines into the spdlog logger (whose sink does the I/O and holds its own
//     mutex, on this thread only).
//
// spdlog's own async logger is not used on the tick path: its queue takes a
// mutex shared with its worker and heap-allocates lines over 250 characters.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <fmt/format.h>
#include <memory>
#include <spdlog/spdlog.h>
#include <thread>
#include <vector>

namespace hoist::rt {

class RtLog {
 public:
  static constexpr std::size_t kText = 480;  ///< longest line kept [chars]

  /// `capacity` is rounded up to a power of two; all slots are allocated here.
  explicit RtLog(std::shared_ptr<spdlog::logger> out, std::size_t capacity = 1024)
      : out_(std::move(out)) {
    std::size_t c = 1;
    while (c < capacity) c <<= 1;
    slots_.resize(c);
    mask_ = c - 1;
    level_.store(static_cast<int>(out_->level()), std::memory_order_relaxed);
    thread_ = std::thread([this] { consume(); });
  }
  RtLog(const RtLog&) = delete;
  RtLog& operator=(const RtLog&) = delete;
  ~RtLog() { stop(); }

  bool shouldLog(spdlog::level::level_enum lvl) const {
    return static_cast<int>(lvl) >= level_.load(std::memory_order_relaxed);
  }

  /// Queue one line (producer thread only).  Never blocks, never allocates.
  template <class... Args>
  void log(spdlog::level::level_enum lvl, fmt::format_string<Args...> f, Args&&... args) {
    if (!shouldLog(lvl)) return;
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= slots_.size()) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    Slot& s = slots_[head & mask_];
    const auto r = fmt::format_to_n(s.text.data(), kText, f, std::forward<Args>(args)...);
    s.len = static_cast<std::uint32_t>(r.size < kText ? r.size : kText);
    s.level = lvl;
    head_.store(head + 1, std::memory_order_release);
  }
  template <class... Args>
  void info(fmt::format_string<Args...> f, Args&&... a) { log(spdlog::level::info, f, std::forward<Args>(a)...); }
  template <class... Args>
  void warn(fmt::format_string<Args...> f, Args&&... a) { log(spdlog::level::warn, f, std::forward<Args>(a)...); }
  template <class... Args>
  void error(fmt::format_string<Args...> f, Args&&... a) { log(spdlog::level::err, f, std::forward<Args>(a)...); }
  template <class... Args>
  void debug(fmt::format_string<Args...> f, Args&&... a) { log(spdlog::level::debug, f, std::forward<Args>(a)...); }

  /// Lines dropped because the ring was full.
  std::int64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

  /// Wait (up to 2 s) until every queued line has been written, then flush.
  void flush() {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (tail_.load(std::memory_order_acquire) != head_.load(std::memory_order_acquire) &&
           std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    out_->flush();
  }

  /// Drain what is queued and end the consumer thread (idempotent).
  void stop() {
    if (!thread_.joinable()) return;
    stop_.store(true, std::memory_order_release);
    thread_.join();
    out_->flush();
  }

 private:
  struct Slot {
    std::array<char, kText> text{};
    std::uint32_t len = 0;
    spdlog::level::level_enum level = spdlog::level::info;
  };

  void drain() {
    std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t head = head_.load(std::memory_order_acquire);
    std::int64_t dropped_now = dropped_.load(std::memory_order_relaxed);
    if (dropped_now > dropped_reported_) {
      out_->warn("{} log lines dropped (real-time log ring full)", dropped_now - dropped_reported_);
      dropped_reported_ = dropped_now;
    }
    for (; tail != head; ++tail) {
      const Slot& s = slots_[tail & mask_];
      out_->log(s.level, "{}", fmt::string_view(s.text.data(), s.len));
    }
    tail_.store(tail, std::memory_order_release);
  }

  void consume() {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    drain();
  }

  std::shared_ptr<spdlog::logger> out_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::int64_t> dropped_{0};
  std::int64_t dropped_reported_ = 0;  // consumer only
  std::atomic<int> level_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hoist::rt
