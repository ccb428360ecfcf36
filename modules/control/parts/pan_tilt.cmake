# Pan-tilt tracking ([T]): ViSP's point servo (baseline) and the predictive law with a
# planar target Kalman filter (CV / CA / Singer), latency compensation, search and reacquisition; the
# waypoint particle filter (the random path's Bayes reference for replays).
list(APPEND control_sources src/pan_tilt_servo.cpp src/waypoint_particle_filter.cpp)
list(APPEND control_tests test/pan_tilt_servo_test.cpp)
