// fixture: a tool including a header of a service/ library folder by its include name
#include "hoist/service/twin/twin_core.hpp"
