# Pan-tilt tracking ([T], issue 6): short seeded runs of each shipped path, limits, occlusion.
list(APPEND scenarios_tests pan_tilt_test.cpp)
