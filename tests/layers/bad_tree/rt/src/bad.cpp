// fixture: rt/ including a daemon header
#include "shaft_twin.hpp"
#include <cstdint>
