# Ball catching ([L] §VI.C): Cartesian robot interface with [L]'s limits, simulated
# Cartesian stage and vpViper850 arm back ends (IK + joint limits on every set point).
list(APPEND robots_sources src/cartesian_robot.cpp)
list(APPEND robots_tests test/cartesian_robot_test.cpp)
