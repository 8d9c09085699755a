// hoist-timing-test -- the soft-real-time check of a running hoist-twind on a
// deployment machine (see timing_cli.cpp and timing_test.hpp).  The same
// program is reachable as `hoist-replay --timing-test`.
#include "timing_cli.hpp"

int main(int argc, char** argv) { return hoist::replay::timingTestMain(argc, argv, "hoist-timing-test"); }
