// fixture: service/core reaching up into the twin, the daemon and LCM
#include "hoist/service/twin/twin_core.hpp"
#include "hoist/service/core/config.hpp"
#include "shaft_twin.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/cage_state_t.hpp"

namespace hoist::service::inline core {  // fixture: the folder's namespace (allowed)
}  // namespace hoist::service::core
