# Ball catching: a short seeded catch session end to end (rendered images, detector, tracker,
# planner, stage and Viper850 arm back ends), paced and unpaced runs, the telemetry's gate decisions.
list(APPEND scenarios_tests ball_catching_test.cpp)
