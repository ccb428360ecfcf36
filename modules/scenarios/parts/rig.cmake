# Default simulated rigs: truth for rendering, calibration for estimation, one loader.
list(APPEND scenarios_sources src/simulated_rig.cpp)
list(APPEND scenarios_tests test/simulated_rig_test.cpp)
