# Mobile capture: short seeded captures, the filter test, the localisation sweep, config errors, the
# run paced and unpaced through the scheduler, the telemetry against the run's counts.
list(APPEND scenarios_tests mobile_capture_test.cpp)
