// fixture: a tool choosing its receive path itself (not through hoist::bus::Subscriber)
#include "hoist/bus/udpm_receiver.hpp"
#include "hoist/bus/subscriber.hpp"
