# Table-ball scenario: LQR balancing controller on the estimated ball state (tilt-rate input).
list(APPEND control_sources src/table_balancer.cpp)
list(APPEND control_tests test/table_balancer_test.cpp)
