# Table-ball scenario: the arm-held table as a delayed, rate- and angle-limited two-angle tilt.
list(APPEND robots_sources src/table_tilt.cpp)
list(APPEND robots_tests test/table_tilt_test.cpp)
