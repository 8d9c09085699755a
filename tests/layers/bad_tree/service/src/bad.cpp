// fixture: service/ reaching into tools/ by a target's include dir
#include "hoist/study/sweep.hpp"
#include "hoist/params.hpp"
