// The project's own udpm receive path: see hoist/bus/udpm_receiver.hpp.
#include "hoist/bus/udpm_receiver.hpp"

#include "hoist/bus/lcm_util.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <linux/filter.h>
#include <linux/sock_diag.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <sys/time.h>
#include <unistd.h>

namespace hoist::bus {

namespace {
constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr std::size_t kMaxChannel = 63;            // LCM_MAX_CHANNEL_NAME_LENGTH
}  // namespace

bool parseUdpmUrl(const std::string& url, UdpmUrl& out, std::string& why) {
  out = UdpmUrl{};
  if (url.empty()) return true;
  const std::string scheme = "udpm://";
  if (url.compare(0, scheme.size(), scheme) != 0) {
    why = "not a udpm:// URL";
    return false;
  }
  std::string rest = url.substr(scheme.size());
  std::string query;
  if (const auto q = rest.find('?'); q != std::string::npos) {
    query = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }
  if (!rest.empty()) {
    const auto colon = rest.find(':');
    out.group = rest.substr(0, colon);
    if (colon != std::string::npos) {
      char* end = nullptr;
      const long p = std::strtol(rest.c_str() + colon + 1, &end, 10);
      if (!end || *end != '\0' || p < 1 || p > 65535) {
        why = "bad port in " + url;
        return false;
      }
      out.port = static_cast<int>(p);
    }
  }
  in_addr a{};
  if (inet_pton(AF_INET, out.group.c_str(), &a) != 1 || (ntohl(a.s_addr) >> 28) != 0xE) {
    why = "not an IPv4 multicast group: " + out.group;
    return false;
  }
  std::size_t pos = 0;
  while (pos < query.size()) {
    const auto amp = query.find('&', pos);
    const std::string kv = query.substr(pos, amp == std::string::npos ? std::string::npos : amp - pos);
    pos = amp == std::string::npos ? query.size() : amp + 1;
    const auto eq = kv.find('=');
    if (eq == std::string::npos) continue;
    if (kv.substr(0, eq) == "recv_buf_size") {
      char* end = nullptr;
      const long n = std::strtol(kv.c_str() + eq + 1, &end, 10);
      if (!end || *end != '\0' || n < 0 || n > (1L << 30)) {
        why = "bad recv_buf_size in " + url;
        return false;
      }
      out.recv_buf_size = static_cast<int>(n);
    } else if (kv.substr(0, eq) == "ttl") {
      char* end = nullptr;
      const long n = std::strtol(kv.c_str() + eq + 1, &end, 10);
      if (!end || *end != '\0' || n < 0 || n > 255) {
        why = "bad ttl in " + url;
        return false;
      }
      out.ttl = static_cast<int>(n);
    }
  }
  return true;
}

UdpmReceiver::~UdpmReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpmReceiver::open(const UdpmUrl& url, std::string& why, int default_rcvbuf) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    why = std::string("socket: ") + std::strerror(errno);
    return false;
  }
  slots_.assign(static_cast<std::size_t>(kBatch) * kSlotBytes, 0);  // drain()'s batch buffers
  const int one = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
#ifdef SO_REUSEPORT
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one);
#endif
  const int want = url.recv_buf_size > 0 ? url.recv_buf_size : default_rcvbuf;
  if (want > 0) {
#ifdef SO_RCVBUFFORCE
    if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want) != 0)
#endif
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);
  }
  socklen_t optlen = sizeof rcvbuf_;
  if (::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf_, &optlen) != 0) rcvbuf_ = 0;
#ifdef SO_RXQ_OVFL
  ::setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one);
#endif
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  addr.sin_port = htons(static_cast<std::uint16_t>(url.port));
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    why = std::string("bind to port ") + std::to_string(url.port) + ": " + std::strerror(errno);
    return false;
  }
  ip_mreq mreq{};
  inet_pton(AF_INET, url.group.c_str(), &mreq.imr_multiaddr);
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0) {
    why = std::string("join ") + url.group + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

bool UdpmReceiver::acceptOnlySuffix(std::string_view suffix, const std::vector<std::size_t>& prefix_lengths,
                                    std::string& why) {
  // Classic BPF on a UDP socket sees the datagram from its UDP header: the
  // LCM header starts at offset 8, the channel name at 16.  For each prefix
  // length P, compare the bytes suffix + NUL at 16 + P (4 at a time, then
  // single bytes); any mismatch jumps to the next length, a full match
  // accepts, and after the last length the datagram is dropped in the
  // kernel.  A load past the end of a short datagram drops it too.
  if (fd_ < 0) {
    why = "not open";
    return false;
  }
  std::string want(suffix);
  want.push_back('\0');
  std::vector<sock_filter> prog;
  for (std::size_t P : prefix_lengths) {
    if (P + want.size() > kMaxChannel + 1) continue;  // no valid channel that long
    const std::size_t base = 16 + P;
    // Build the block first, then fix its "mismatch" jumps to point past it.
    std::vector<sock_filter> block;
    std::vector<std::size_t> fixups;
    std::size_t i = 0;
    while (i < want.size()) {
      const std::size_t left = want.size() - i;
      if (left >= 4) {
        std::uint32_t w = 0;
        for (int k = 0; k < 4; ++k) w = (w << 8) | static_cast<std::uint8_t>(want[i + k]);
        block.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, static_cast<std::uint32_t>(base + i)));
        block.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, w, 0, 0));
        i += 4;
      } else {
        block.push_back(BPF_STMT(BPF_LD | BPF_B | BPF_ABS, static_cast<std::uint32_t>(base + i)));
        block.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, static_cast<std::uint8_t>(want[i]), 0, 0));
        i += 1;
      }
      fixups.push_back(block.size() - 1);
    }
    block.push_back(BPF_STMT(BPF_RET | BPF_K, 0xFFFFFFFFu));  // match: accept the whole datagram
    for (std::size_t f : fixups) block[f].jf = static_cast<std::uint8_t>(block.size() - 1 - f);
    prog.insert(prog.end(), block.begin(), block.end());
  }
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, 0));  // no length matched: drop
  if (prog.size() > BPF_MAXINSNS) {
    why = "too many prefix lengths for a kernel filter";
    return false;
  }
  sock_fprog fprog{static_cast<unsigned short>(prog.size()), prog.data()};
  if (::setsockopt(fd_, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0) {
    why = std::string("SO_ATTACH_FILTER: ") + std::strerror(errno);
    return false;
  }
  // Datagrams queued before the filter was attached: read and drop them.
  std::uint8_t junk[16];
  while (::recv(fd_, junk, sizeof junk, MSG_DONTWAIT) >= 0) {
  }
  return true;
}

std::int64_t UdpmReceiver::refreshKernelDrops() {
#if defined(SO_MEMINFO)
  std::uint32_t mem[SK_MEMINFO_VARS] = {};
  socklen_t len = sizeof mem;
  if (fd_ >= 0 && ::getsockopt(fd_, SOL_SOCKET, SO_MEMINFO, mem, &len) == 0 &&
      len >= (SK_MEMINFO_DROPS + 1) * sizeof(std::uint32_t))
    kernel_drops_ = mem[SK_MEMINFO_DROPS];
#endif
  return kernel_drops_;
}

void UdpmReceiver::add(const std::string& channel, RawHandler handler) {
  routes_.push_back(Route{channel, std::move(handler)});
  // Start-up only: rebuild the index (the vector may have moved the names).
  index_.clear();
  index_.reserve(routes_.size());
  for (const Route& r : routes_) index_.emplace(std::string_view(r.channel), &r);
}

void UdpmReceiver::addMatching(std::function<bool(std::string_view)> match, RawHandler handler) {
  matchers_.push_back(MatchRoute{std::move(match), std::move(handler)});
  name_.reserve(kMaxChannel + 1);
}

int UdpmReceiver::drain(int max) {
  if (slots_.empty()) return 0;  // not open
  int n = 0;
  while (n < max) {
    // recvmmsg: up to kBatch datagrams in one system call (system calls are
    // what costs on a virtual machine), each with (SO_RXQ_OVFL) the socket's
    // drop counter.
    const int want = std::min(kBatch, max - n);
    for (int i = 0; i < want; ++i) {
      iov_[i] = iovec{slots_.data() + static_cast<std::size_t>(i) * kSlotBytes, kSlotBytes};
      msghdr& mh = msgs_[i].msg_hdr;
      mh = msghdr{};
      mh.msg_iov = &iov_[i];
      mh.msg_iovlen = 1;
      mh.msg_control = control_[i].b;
      mh.msg_controllen = sizeof control_[i].b;
      msgs_[i].msg_len = 0;
    }
    const int got = ::recvmmsg(fd_, msgs_.data(), static_cast<unsigned>(want), MSG_DONTWAIT, nullptr);
    if (got <= 0) break;  // EAGAIN: nothing pending (or an error: try again next time)
    for (int i = 0; i < got; ++i) {
      msghdr& mh = msgs_[i].msg_hdr;
#ifdef SO_RXQ_OVFL
      for (cmsghdr* c = CMSG_FIRSTHDR(&mh); c; c = CMSG_NXTHDR(&mh, c))
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
          std::uint32_t drops = 0;
          std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
          kernel_drops_ = drops;
        }
#endif
      dispatch(slots_.data() + static_cast<std::size_t>(i) * kSlotBytes, msgs_[i].msg_len,
               (mh.msg_flags & MSG_TRUNC) != 0);
    }
    n += got;
    if (got < want) break;  // the queue is empty
  }
  return n;
}

void UdpmReceiver::dispatch(std::uint8_t* data, std::size_t size, bool truncated) {
  ++received_;
  if (size < 9 || truncated) {
    ++malformed_;
    return;
  }
  std::uint32_t magic = 0;
  std::memcpy(&magic, data, 4);
  if (ntohl(magic) != kMagicShort) {
    ++malformed_;  // fragments ("LC03") and foreign traffic
    return;
  }
  const char* name = reinterpret_cast<const char*>(data + 8);
  const std::size_t room = std::min(size - 8, kMaxChannel + 1);
  const void* nul = std::memchr(name, '\0', room);
  if (!nul) {
    ++malformed_;
    return;
  }
  const std::size_t name_len = static_cast<const char*>(nul) - name;
  const auto it = index_.find(std::string_view(name, name_len));
  const Route* route = it == index_.end() ? nullptr : it->second;
  const MatchRoute* matched = nullptr;
  if (!route)
    for (const MatchRoute& m : matchers_)
      if (m.match(std::string_view(name, name_len))) {
        matched = &m;
        break;
      }
  if (!route && !matched) {
    ++ignored_;
    return;
  }
  lcm::ReceiveBuffer rb{};
  rb.data = data + 8 + name_len + 1;
  rb.data_size = static_cast<std::uint32_t>(size - 8 - name_len - 1);
  timeval tv{};
  ::gettimeofday(&tv, nullptr);
  rb.recv_utime = static_cast<std::int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
  if (route) {
    route->handler(&rb, route->channel);
  } else {
    name_.assign(name, name_len);  // capacity reserved by addMatching: no allocation
    matched->handler(&rb, name_);
  }
}

std::unique_ptr<UdpmReceiver> openUdpmReceiver(const std::string& url, std::string& why, int default_rcvbuf) {
  UdpmUrl u;
  if (!parseUdpmUrl(url, u, why)) {
    why.clear();
    return nullptr;
  }
  auto rx = std::make_unique<UdpmReceiver>();
  if (!rx->open(u, why, default_rcvbuf)) {
    why = "cannot open the LCM receive socket for " + describeLcmUrl(url) + ": " + why;
    return nullptr;
  }
  return rx;
}

}  // namespace hoist::bus
