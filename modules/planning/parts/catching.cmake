# Ball catching ([L] §VI.C): crossing prediction of a tracked flight with a moving
# box-front plane (drag / no drag, linearised covariance), time-optimal synchronised motion
# profiles from any state, and the interception planner (replan, commit, give up, go home).
list(APPEND planning_sources src/motion_profile.cpp src/crossing.cpp src/catch_planner.cpp)
list(APPEND planning_tests test/motion_profile_test.cpp test/crossing_test.cpp test/catch_planner_test.cpp)
