# Pan-tilt tracking ([T]): ViSP's point servo (baseline) and the predictive law on the planar target
# filter (tracking::PlanarTargetFilter), latency compensation, search and reacquisition.
list(APPEND control_sources src/pan_tilt_servo.cpp)
list(APPEND control_tests test/pan_tilt_servo_test.cpp)
