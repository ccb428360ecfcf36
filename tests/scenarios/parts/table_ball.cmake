# Table-ball balancing ([M]): short seeded closed-loop runs of runTableBall (as fast as possible
# and paced, telemetry counts against the summary).
list(APPEND scenarios_tests table_ball_test.cpp)
