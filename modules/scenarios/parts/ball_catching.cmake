# Ball catching ([L] §VI.C, issue 5): the catch session as library code (throw distribution with
# drag, rendered unsynchronised cameras, blob detector, viewline tracker, interception planner,
# simulated stage/arm, oracle reachability, metrics) and its live view (vpDisplayX, --display only).
list(APPEND scenarios_sources src/ball_catching.cpp src/ball_catching_display.cpp)
