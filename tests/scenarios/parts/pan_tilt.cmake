# Pan-tilt tracking ([T]): short seeded runs of each shipped path, limits, occlusion and telemetry, paced vs fast.
list(APPEND scenarios_tests pan_tilt_test.cpp)
