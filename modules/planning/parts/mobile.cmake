# Mobile capture ([K] eq 30): shortest-time capture point of a predicted ground object.
list(APPEND planning_sources src/capture_planner.cpp)
list(APPEND planning_tests test/capture_planner_test.cpp)
