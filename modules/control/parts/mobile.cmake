# Mobile capture ([K]): go-to-point base law, IK head pointing, search pattern.
list(APPEND control_sources src/mobile_capture_control.cpp)
list(APPEND control_tests test/mobile_capture_control_test.cpp)
