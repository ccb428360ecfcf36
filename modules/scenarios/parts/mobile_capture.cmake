# Mobile capture ([K], SPEC §4, issue 8): the scenario loop, oracle, filter test, ground-localisation sweep,
# and the live view (vpDisplayX, only used with --display).
list(APPEND scenarios_sources src/mobile_capture.cpp src/mobile_capture_display.cpp)
