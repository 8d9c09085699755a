// The output watch of hoist-twind: see output_watch.hpp.
#include "output_watch.hpp"

#include <algorithm>

#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "shaft_twin.hpp"

namespace hoist::service::inline app {

namespace asio = boost::asio;

OutputWatch::~OutputWatch() {
  if (fd_.is_open()) fd_.release();  // receiver_ closes it
}

void OutputWatch::open(const std::string& url, const std::vector<std::unique_ptr<ShaftTwin>>& shafts) {
  bus::UdpmUrl out_udpm;
  std::string out_why;
  if (!bus::parseUdpmUrl(url, out_udpm, out_why)) {
    out_->warn("[service] lcm_url_out {} is not a udpm:// URL ({}): a second publisher on the output "
               "channels (DUPLICATE_PUBLISHER) cannot be detected",
               bus::describeLcmUrl(url), out_why);
    return;
  }
  receiver_ = std::make_unique<bus::UdpmReceiver>();
  if (!receiver_->open(out_udpm, out_why)) {
    out_->warn("cannot watch the output URL {} for a second publisher ({}); DUPLICATE_PUBLISHER "
               "detection is off",
               bus::describeLcmUrl(url), out_why);
    receiver_.reset();
    return;
  }
  for (auto& s : shafts) s->watchOwnOutputs(receiver_.get());
  // All our outputs arrive on that group: let the kernel drop all but
  // the HOIST_HEALTH channels, so that the loop does not wake for its
  // own cage and shape messages (the point of lcm_url_out).
  std::vector<std::size_t> lens;
  for (auto& s : shafts) {
    const std::size_t P = s->channels().health.size() - bus::kChannelHealth.size();
    if (std::find(lens.begin(), lens.end(), P) == lens.end()) lens.push_back(P);
  }
  if (!receiver_->acceptOnlySuffix(bus::kChannelHealth, lens, out_why))
    out_->warn("no kernel filter on the output-URL watch ({}): it reads every output datagram", out_why);
  fd_.assign(receiver_->fd());
  arm();
}

void OutputWatch::stop() {
  stopped_ = true;
  if (fd_.is_open()) {
    fd_.cancel();
    fd_.release();
  }
}

void OutputWatch::arm() {
  fd_.async_wait(asio::posix::stream_descriptor::wait_read,
                 [this](const boost::system::error_code& ec) { onReadable(ec); });
}

void OutputWatch::onReadable(const boost::system::error_code& ec) {
  if (stopped_ || ec == asio::error::operation_aborted) return;
  if (ec) {
    log_.error("output-URL watch descriptor error: {}; DUPLICATE_PUBLISHER detection stops", ec.message());
    return;
  }
  // Mostly our own outputs come back here (loopback); bounded like the input.
  receiver_->drain(256);
  if (!stopped_) arm();
}

}  // namespace hoist::service::app
