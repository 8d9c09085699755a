// fixture: a tool including the daemon's header by its include name
#include "hoist/service/alarms.hpp"
#include "hoist/contract/alarm_command.hpp"
