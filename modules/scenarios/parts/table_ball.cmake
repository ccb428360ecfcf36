# Table-ball balancing scenario ([M], issue 7): observer, closed loop, metrics and the live view
# as library code (the app main stays thin; the tuning tool runs runTableBall in-process).
list(APPEND scenarios_sources src/table_ball_observer.cpp src/table_ball.cpp src/table_ball_display.cpp
  src/table_edge_tracker.cpp)
list(APPEND scenarios_tests test/table_ball_observer_test.cpp)
