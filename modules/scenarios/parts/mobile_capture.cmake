# Mobile capture ([K], SPEC §4): config, world (object, floor, robot, rendered head camera), the loop
# on the scenario runtime with its oracle, and the metrics (filter test, localisation sweep, batch).
list(APPEND scenarios_sources mobile_capture/config.cpp mobile_capture/world.cpp mobile_capture/loop.cpp
  mobile_capture/metrics.cpp)
# The chase's perception and commands (chase.h): one piece for the simulated loop and the footage session.
list(APPEND scenarios_sources mobile_capture/chase.cpp)
list(APPEND scenarios_tests test/mobile_capture_chase_test.cpp)
# --record / --replay: the head camera's frames and the object's truth per run (session recordings).
list(APPEND scenarios_sources mobile_capture/recording.cpp)
list(APPEND scenarios_tests test/mobile_capture_sources_test.cpp)
# Unit and meaning of every key its config reader reads (docs/config_reference.md is generated from it).
list(APPEND scenarios_sources mobile_capture/config_keys.cpp)
list(APPEND scenarios_tests test/mobile_capture_faults_test.cpp)
# The robot's side of the faults: commands through the fault plan, the base's command watchdog.
list(APPEND scenarios_sources mobile_capture/robot_link.cpp)
# Footage (images, video, v4l2): one session with the robot held at its start pose (a fixed camera).
list(APPEND scenarios_sources mobile_capture/footage.cpp)
list(APPEND scenarios_tests test/mobile_capture_footage_test.cpp)
