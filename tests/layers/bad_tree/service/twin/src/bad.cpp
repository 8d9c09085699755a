// fixture: service/twin reaching into service/lcm and LCM's types
#include "hoist/service/messages.hpp"
#include "hoist/service/config.hpp"
#include "hoist/service/twin_core.hpp"
#include <lcm/lcm-cpp.hpp>
