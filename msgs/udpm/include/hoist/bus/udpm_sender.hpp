// hoist/bus/udpm_sender.hpp -- hoist-twind's own publisher for LCM's UDP multicast
// transport (udpm://), batching the per-tick outputs into sendmmsg calls.
//
// Why: with hundreds of shafts, publishing HOIST_CAGE is one
// sendmsg per shaft and tick, and on a virtual machine every system call is
// expensive (the profile in docs/multishaft-report.md).  queue() keeps a
// message (header + a pointer to the caller's encoded bytes, which must stay
// unchanged until the next flush()); flush() sends everything queued with
// sendmmsg, up to kSlots per call.  send() publishes one message at once.
//
// Wire format: LCM's "short" datagram, as udpm_receiver.hpp reads it:
//   u32 magic 0x4c433032 ("LC02") | u32 sequence number | channel, NUL | payload
// (big-endian), sent to the group:port of the URL (sendto-style, as LCM),
// IP_MULTICAST_TTL from the URL's ttl
// (default 0: nothing leaves the machine), multicast loop on.  Messages too
// large for one datagram (LCM would fragment them) are refused: the caller
// publishes those through LCM.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <sys/socket.h>
#include <netinet/in.h>
#include <sys/uio.h>

#include "hoist/bus/udpm_receiver.hpp"

namespace hoist::bus {

class UdpmSender {
 public:
  static constexpr int kSlots = 64;                 ///< messages queued at most (then flushed)
  static constexpr std::size_t kMaxPayload = 65000;  ///< larger: use LCM (fragmentation)

  UdpmSender() = default;
  ~UdpmSender();
  UdpmSender(const UdpmSender&) = delete;
  UdpmSender& operator=(const UdpmSender&) = delete;

  bool open(const UdpmUrl& url, std::string& why);
  /// Publish now; false if the kernel refused it (or it is too large).
  bool send(const std::string& channel, const std::uint8_t* data, std::size_t len);
  /// Publish at the next flush(); `data` must stay valid and unchanged until
  /// then.  A message that fails then adds one to *failures.  False (nothing
  /// queued) if it is too large or the channel name too long.
  bool queue(const std::string& channel, const std::uint8_t* data, std::size_t len, std::int64_t* failures);
  /// Send what is queued; returns how many messages failed.
  int flush();
  int queued() const { return count_; }
  std::int64_t sent() const { return sent_; }
  std::int64_t systemCalls() const { return calls_; }

 private:
  struct Header {
    std::uint8_t b[8 + 64];  // magic, seqno, channel (<= 63 bytes) + NUL
    std::size_t len = 0;
  };
  bool fill(Header& h, const std::string& channel);
  int fd_ = -1;
  sockaddr_in dest_{};
  std::uint32_t seq_ = 0;
  int count_ = 0;
  std::array<Header, kSlots> headers_{};
  std::array<std::array<iovec, 2>, kSlots> iov_{};
  std::array<mmsghdr, kSlots> msgs_{};
  std::array<std::int64_t*, kSlots> failures_{};
  std::int64_t sent_ = 0, calls_ = 0;
};

}  // namespace hoist::bus
