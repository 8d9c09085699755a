// fixture: msgs/ reaching up into service/ and tools/
#include "hoist/service/alarms.hpp"
#include "../../tools/replay/timing_report.hpp"
#include "hoist/contract/alarm_command.hpp"
