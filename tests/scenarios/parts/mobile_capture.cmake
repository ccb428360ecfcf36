# Mobile capture (issue 8): a short seeded capture, the filter test, the localisation sweep, config errors.
list(APPEND scenarios_tests mobile_capture_test.cpp)
