// fixture: service/twin reaching into service/lcm and LCM's types
#include "hoist/service/lcm/messages.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/twin/twin_core.hpp"
#include <lcm/lcm-cpp.hpp>

namespace hoist::svc {  // fixture: not the folder's namespace
}  // namespace hoist::svc
