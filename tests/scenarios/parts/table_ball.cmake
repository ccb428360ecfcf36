# Table-ball balancing ([M], issue 7): a short seeded closed-loop run of runTableBall.
list(APPEND scenarios_tests table_ball_test.cpp)
