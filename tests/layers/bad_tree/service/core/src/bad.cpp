// fixture: service/core reaching up into the twin, the daemon and LCM
#include "hoist/service/twin_core.hpp"
#include "hoist/service/config.hpp"
#include "shaft_twin.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/cage_state_t.hpp"
