// The miss record: see miss_record.hpp.
#include "miss_record.hpp"

namespace hoist::service::inline app {

const MissRecord* MissLog::worst() const {
  const MissRecord* w = nullptr;
  for (std::size_t i = 0; i < kept(); ++i) {
    const MissRecord& r = at(i);
    if (!w || r.late_us > w->late_us) w = &r;
  }
  return w;
}

}  // namespace hoist::service::app
