// hoist/rt/latest_mailbox.hpp -- a single-slot, lock-free, wait-free
// mailbox between exactly one writer thread and one reader thread: the
// reader always gets the NEWEST item; an item the reader has not taken yet
// is replaced by the next one (counted by the writer as dropped), so a slow
// reader never builds a backlog.  The realtime_tools RealtimeBuffer idea,
// without its mutex: a triple buffer.
//
//   writer:  T& slot = box.writeSlot(); ...fill slot...; bool replaced = box.publish();
//   reader:  if (const T* item = box.take()) { ...use *item until the next take()... }
//
// Three slots of T, allocated (copied from a prototype) at construction; the
// hand-over is one atomic exchange of a slot index on each side, so neither
// side ever blocks, allocates or makes a system call.  Acquire/release on
// that exchange orders the slot's contents (ThreadSanitizer sees it too).
#pragma once

#include <array>
#include <atomic>

namespace hoist::rt {

template <class T>
class LatestMailbox {
 public:
  /// Every slot is a copy of `prototype` (sizes its buffers once).
  explicit LatestMailbox(const T& prototype) : slots_{prototype, prototype, prototype} {}
  LatestMailbox(const LatestMailbox&) = delete;
  LatestMailbox& operator=(const LatestMailbox&) = delete;

  /// Writer: the slot to fill next (owned by the writer until publish()).
  T& writeSlot() { return slots_[write_]; }
  /// Writer: hand the filled slot over.  True if it replaced an item the
  /// reader had not taken (a dropped item).
  bool publish() {
    const unsigned old = middle_.exchange(write_ | kFresh, std::memory_order_acq_rel);
    write_ = old & kIndex;
    return (old & kFresh) != 0;
  }
  /// Reader: the newest item if one arrived since the last take(), else
  /// nullptr.  The item stays valid (and unchanged) until the next take().
  const T* take() {
    if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return nullptr;
    const unsigned old = middle_.exchange(read_, std::memory_order_acq_rel);
    read_ = old & kIndex;
    return &slots_[read_];
  }
  /// Reader or writer: whether an untaken item is waiting (a hint).
  bool pending() const { return (middle_.load(std::memory_order_acquire) & kFresh) != 0; }

 private:
  static constexpr unsigned kFresh = 4u, kIndex = 3u;
  std::array<T, 3> slots_;
  unsigned write_ = 0;                 // writer's slot
  unsigned read_ = 1;                  // reader's slot
  std::atomic<unsigned> middle_{2u};   // the slot in between (| kFresh when unread)
};

}  // namespace hoist::rt
