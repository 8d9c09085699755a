// fixture: the model including a header of another layer
#include "hoist/params.hpp"
#include "hoist/io/config.hpp"
