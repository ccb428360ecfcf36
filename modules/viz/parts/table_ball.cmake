# Table-ball balancing: the head-camera view and the top view of the table.
list(APPEND viz_sources src/table_ball_display.cpp)
