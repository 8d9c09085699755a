// fixture: a tools/ header (tests/layers/check_layers_selftest.cmake)
