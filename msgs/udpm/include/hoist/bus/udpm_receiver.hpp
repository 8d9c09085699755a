// hoist/bus/udpm_receiver.hpp -- the project's own receive path for LCM's
// UDP multicast transport (udpm://), in place of LCM 1.3.1's: hoist-twind
// (inputs, and its own outputs on lcm_url_out), hoist-dash, hoist-mqtt,
// hoist-monitor and hoist-timing-test's listener.  Target hoist_lcm_udpm (msgs/CMakeLists.txt; not installed).
//
// Why: LCM 1.3.1 keeps, per lcm_t, a hash table entry (channel name string +
// handler array) for EVERY channel name it has ever received on the group,
// subscribed or not, and never frees them (lcm.c lcm_get_handlers): a sender
// cycling through distinct channel names grows the memory of every
// subscriber without bound (about 11 MB per 100k names).  This receiver
// reads the datagrams itself and dispatches only the channels it was given,
// by exact name (add(): no regular expressions either, and nothing is
// allocated per datagram) or by a predicate on the name (addMatching(): the
// name is copied into a preallocated string; used by the tools that discover
// prefixes): nothing is stored per name, so memory stays flat whatever
// arrives.  LCM is still used to publish
// (lcm::LCM creates no receive socket and no receive thread while nobody
// subscribes or asks for its file descriptor).
//
// Wire format (lcm-proj/lcm, lcm/lcm_udpm.c, udpm_util.h): a "short"
// datagram is  u32 magic 0x4c433032 ("LC02") | u32 sequence number |
// channel name, NUL-terminated | payload  (big-endian); on Linux every
// message up to 65 499 bytes is sent short.  Fragmented messages (magic
// "LC03", larger than that) are never inputs of the twin: they are counted
// and dropped.  Channel names longer than 63 bytes (LCM's own limit) or
// without a terminator are dropped and counted.
//
// Socket options as LCM's: SO_REUSEADDR (+ SO_REUSEPORT) so that other LCM
// programs on the machine share the port, bound to INADDR_ANY:port, joined
// to the group on INADDR_ANY; SO_RCVBUF from the URL's recv_buf_size, else
// the caller's default (hoist-twind sizes it for 200 ms of its inputs: a
// tick of many shafts must not overflow it), asked for with
// SO_RCVBUFFORCE first (root / CAP_NET_ADMIN may exceed net.core.rmem_max),
// then SO_RCVBUF (capped at rmem_max by the kernel); rcvbuf() is what the
// kernel granted.  SO_RXQ_OVFL makes the kernel report, with every
// datagram, how many it dropped on this socket because the buffer was full:
// kernelDrops() (the "inputs lost" that no sequence number can attribute to
// a shaft when the lost datagram was someone else's).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <string_view>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unordered_map>
#include <vector>

namespace hoist::bus {

using RawHandler = std::function<void(const lcm::ReceiveBuffer*, const std::string&)>;

/// Where a shaft registers its input channels (exact names).
class InputRouter {
 public:
  virtual ~InputRouter() = default;
  virtual void add(const std::string& channel, RawHandler handler) = 0;
};

/// Parsed udpm URL.  parseUdpmUrl() returns false (and `why`) for anything
/// else; "" is LCM's default, udpm://239.255.76.67:7667?ttl=0.
struct UdpmUrl {
  std::string group = "239.255.76.67";
  int port = 7667;
  int recv_buf_size = 0;  ///< bytes, 0 = the system default
  int ttl = 0;            ///< multicast TTL (publishing), 0 = this machine only
};
bool parseUdpmUrl(const std::string& url, UdpmUrl& out, std::string& why);

class UdpmReceiver final : public InputRouter {
 public:
  UdpmReceiver() = default;
  ~UdpmReceiver() override;
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;

  /// Open the socket (non-blocking); false and `why` on failure.
  /// `default_rcvbuf` [bytes] applies when the URL gives no recv_buf_size.
  bool open(const UdpmUrl& url, std::string& why, int default_rcvbuf = 0);
  /// The receive buffer the kernel granted [bytes] (getsockopt SO_RCVBUF).
  int rcvbuf() const { return rcvbuf_; }
  /// Datagrams the kernel dropped on this socket (buffer full), as last
  /// reported by SO_RXQ_OVFL: each datagram carries the count at the time it
  /// was queued, so drops show with the next datagram read after them.
  std::int64_t kernelDrops() const { return kernel_drops_; }
  /// Ask the kernel for the current drop count (SO_MEMINFO,
  /// SK_MEMINFO_DROPS; not for the loop: a system call); updates and returns
  /// kernelDrops().
  std::int64_t refreshKernelDrops();
  int fd() const { return fd_; }
  void add(const std::string& channel, RawHandler handler) override;
  /// Every channel whose name satisfies `match` (checked after the exact
  /// names).  The handler's channel string is reused between calls.
  void addMatching(std::function<bool(std::string_view)> match, RawHandler handler);
  /// Read and dispatch at most `max` datagrams, up to kBatch per system
  /// call (recvmmsg); returns how many were read (0: nothing pending).  No
  /// allocation (the batch buffers are allocated by open()).
  int drain(int max);
  /// Kernel-side filter (classic BPF, SO_ATTACH_FILTER), for a socket that
  /// only needs a few channels of a busy group: the kernel queues only the
  /// datagrams whose channel name is some prefix of one of `prefix_lengths`
  /// bytes followed by `suffix`, and drops the rest before they cost a
  /// wake-up or a read (hoist-twind's watch of its own HOIST_HEALTH on
  /// lcm_url_out, where all its outputs arrive).  The routes still match the
  /// exact names.  Start-up only (allocates); false and `why` on failure.
  bool acceptOnlySuffix(std::string_view suffix, const std::vector<std::size_t>& prefix_lengths, std::string& why);
  static constexpr int kBatch = 16;  ///< datagrams per recvmmsg

  std::int64_t received() const { return received_; }
  std::int64_t ignored() const { return ignored_; }      ///< datagrams on channels nobody subscribed
  std::int64_t malformed() const { return malformed_; }  ///< bad magic, no/long channel name, fragments

 private:
  struct Route {
    std::string channel;
    RawHandler handler;
  };
  void dispatch(std::uint8_t* data, std::size_t size, bool truncated);
  static constexpr std::size_t kSlotBytes = 65536;  ///< any UDP datagram fits
  int fd_ = -1;
  int rcvbuf_ = 0;
  std::int64_t kernel_drops_ = 0;
  std::vector<Route> routes_;
  struct MatchRoute {
    std::function<bool(std::string_view)> match;
    RawHandler handler;
  };
  std::vector<MatchRoute> matchers_;
  std::string name_;  ///< the channel name for matched routes (capacity reserved)
  std::unordered_map<std::string_view, const Route*> index_;  ///< exact channel name -> route
  std::vector<std::uint8_t> slots_;                           ///< kBatch x kSlotBytes
  std::array<mmsghdr, kBatch> msgs_{};
  std::array<iovec, kBatch> iov_{};
  struct alignas(cmsghdr) Control {
    char b[CMSG_SPACE(sizeof(std::uint32_t))];
  };
  std::array<Control, kBatch> control_{};
  std::int64_t received_ = 0, ignored_ = 0, malformed_ = 0;
};

/// The udpm half of hoist::bus::Subscriber's choice (subscriber.hpp, which
/// the programs use): an opened UdpmReceiver for udpm://
/// (and LCM's default); nullptr with `why` empty for other providers (use
/// LCM's subscribe); nullptr with `why` set when the socket cannot be opened
/// (the message names the URL).  `default_rcvbuf` [bytes]: as open()'s.
std::unique_ptr<UdpmReceiver> openUdpmReceiver(const std::string& url, std::string& why, int default_rcvbuf = 0);

}  // namespace hoist::bus
