// fixture: io/ reaching into tools/ by path
#include "../../tools/replay/timing_report.hpp"
#include <string>
