# Ball catching ([L] §VI.C): the catch session as library code on the scenario runtime (config
# reader, world and cameras as a frame source, registration, the scheduled loop, metrics). Its
# live view is in modules/viz (ball_catching_display).
list(APPEND scenarios_sources
  ball_catching/config.cpp
  ball_catching/detection.cpp
  ball_catching/flight_fit.cpp
  ball_catching/footage.cpp
  ball_catching/loop.cpp
  ball_catching/metrics.cpp
  ball_catching/planner_input.cpp
  ball_catching/recording.cpp
  ball_catching/registration.cpp
  ball_catching/robot_guard.cpp
  ball_catching/world.cpp)
list(APPEND scenarios_tests test/summary_text_test.cpp test/flight_fit_test.cpp test/ball_catching_sources_test.cpp)
# Unit and meaning of every key its config reader reads (docs/config_reference.md is generated from it).
list(APPEND scenarios_sources ball_catching/config_keys.cpp)
list(APPEND scenarios_tests test/ball_catching_faults_test.cpp)
# The catcher on footage: one session over the cameras' frames, no truth (ball_catching/footage.h).
list(APPEND scenarios_tests test/ball_catching_footage_test.cpp)
