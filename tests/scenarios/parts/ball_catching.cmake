# Ball catching (issue 5): a short seeded catch session end to end (rendered images, detector,
# tracker, planner, stage and Viper850 arm back ends).
list(APPEND scenarios_tests ball_catching_test.cpp)
