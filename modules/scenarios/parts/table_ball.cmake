# Table-ball balancing ([M]): the observer and edge tracker, and the scenario in its folder
# (config, world, loop on the runtime scheduler, metrics). The live view is in modules/viz.
list(APPEND scenarios_sources table_ball/observer.cpp
  table_ball/config.cpp table_ball/world.cpp table_ball/loop.cpp table_ball/metrics.cpp
  table_ball/wrist_link.cpp)
list(APPEND scenarios_tests test/table_ball_observer_test.cpp)
# Unit and meaning of every key its config reader reads (docs/config_reference.md is generated from it).
list(APPEND scenarios_sources table_ball/config_keys.cpp)
# The loop on a recording of its head camera (--record / --replay).
list(APPEND scenarios_tests test/table_ball_sources_test.cpp)
list(APPEND scenarios_tests test/table_ball_faults_test.cpp)
# The loop on footage (images, video, v4l2): one session without truth (table_ball/footage.h).
list(APPEND scenarios_sources table_ball/footage.cpp)
list(APPEND scenarios_tests test/table_ball_footage_test.cpp)
