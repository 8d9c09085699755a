// hoist-twind's own udpm publisher: see udpm_sender.hpp.
#include "hoist/bus/udpm_sender.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <cstring>
#include <netinet/in.h>
#include <unistd.h>

namespace hoist::bus {

namespace {
constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
}  // namespace

UdpmSender::~UdpmSender() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpmSender::open(const UdpmUrl& url, std::string& why) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    why = std::string("socket: ") + std::strerror(errno);
    return false;
  }
  const unsigned char ttl = static_cast<unsigned char>(url.ttl);
  const unsigned char loop = 1;
  if (::setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
      ::setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0) {
    why = std::string("multicast options: ") + std::strerror(errno);
    return false;
  }
  // Not connect()ed: a connected socket's multicast is not looped back to
  // this machine's receivers here (Linux 6.x, route via lo), LCM's sendto is.
  dest_ = sockaddr_in{};
  dest_.sin_family = AF_INET;
  dest_.sin_port = htons(static_cast<std::uint16_t>(url.port));
  inet_pton(AF_INET, url.group.c_str(), &dest_.sin_addr);
  for (int i = 0; i < kSlots; ++i) {
    msgs_[i].msg_hdr = msghdr{};
    msgs_[i].msg_hdr.msg_name = &dest_;
    msgs_[i].msg_hdr.msg_namelen = sizeof dest_;
    msgs_[i].msg_hdr.msg_iov = iov_[i].data();
    msgs_[i].msg_hdr.msg_iovlen = 2;
  }
  return true;
}

bool UdpmSender::fill(Header& h, const std::string& channel) {
  if (channel.size() > 63) return false;
  const std::uint32_t magic = htonl(kMagicShort), seq = htonl(seq_++);
  std::memcpy(h.b, &magic, 4);
  std::memcpy(h.b + 4, &seq, 4);
  std::memcpy(h.b + 8, channel.data(), channel.size());
  h.b[8 + channel.size()] = 0;
  h.len = 8 + channel.size() + 1;
  return true;
}

bool UdpmSender::send(const std::string& channel, const std::uint8_t* data, std::size_t len) {
  if (fd_ < 0 || len > kMaxPayload) return false;
  Header h;
  if (!fill(h, channel)) return false;
  iovec iov[2] = {{h.b, h.len}, {const_cast<std::uint8_t*>(data), len}};
  msghdr mh{};
  mh.msg_name = &dest_;
  mh.msg_namelen = sizeof dest_;
  mh.msg_iov = iov;
  mh.msg_iovlen = 2;
  ++calls_;
  if (::sendmsg(fd_, &mh, 0) < 0) return false;
  ++sent_;
  return true;
}

bool UdpmSender::queue(const std::string& channel, const std::uint8_t* data, std::size_t len,
                       std::int64_t* failures) {
  if (fd_ < 0 || len > kMaxPayload || channel.size() > 63) return false;
  if (count_ == kSlots) flush();
  Header& h = headers_[count_];
  fill(h, channel);
  iov_[count_][0] = iovec{h.b, h.len};
  iov_[count_][1] = iovec{const_cast<std::uint8_t*>(data), len};
  failures_[count_] = failures;
  ++count_;
  return true;
}

int UdpmSender::flush() {
  int failed = 0, i = 0;
  while (i < count_) {
    ++calls_;
    const int n = ::sendmmsg(fd_, msgs_.data() + i, static_cast<unsigned>(count_ - i), 0);
    if (n > 0) {
      sent_ += n;
      i += n;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    // Message i was refused: count it and go on with the rest.
    if (failures_[i]) ++*failures_[i];
    ++failed;
    ++i;
  }
  count_ = 0;
  return failed;
}

}  // namespace hoist::bus
