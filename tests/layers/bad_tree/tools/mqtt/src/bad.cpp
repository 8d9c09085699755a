// fixture: a tool reaching into service/ by a relative path and by a
// service/app header name; its own and the contract's headers are fine
#include "../../../service/app/daemon.hpp"
#include "shaft_twin.hpp"
#include "udpm_sender.hpp"
#include "hoist/mqtt/command.hpp"
#include "hoist/contract/alarm_command.hpp"
#include <string>
