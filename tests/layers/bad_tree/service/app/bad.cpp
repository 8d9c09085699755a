// fixture: service/ reaching into tools/ by a relative path
#include "../../tools/mqtt/include/hoist/mqtt/command.hpp"
#include "shaft_twin.hpp"
