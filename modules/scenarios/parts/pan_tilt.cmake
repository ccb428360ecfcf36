# Pan-tilt tracking ([T]): config, world, loop, metrics, telemetry, replay and the app's command, one
# file each under pan_tilt/. Its live view is in the viz module (viz/parts/pan_tilt.cmake).
list(APPEND scenarios_sources
  pan_tilt/command.cpp
  pan_tilt/config.cpp
  pan_tilt/faults.cpp
  pan_tilt/footage.cpp
  pan_tilt/loop.cpp
  pan_tilt/metrics.cpp
  pan_tilt/replay.cpp
  pan_tilt/telemetry.cpp
  pan_tilt/world.cpp)
# Unit and meaning of every key its config reader reads (docs/config_reference.md is generated from it).
list(APPEND scenarios_sources pan_tilt/config_keys.cpp)
# Real footage (ViSP's mire-2) through the pan-tilt perception, against ViSP's vpDot2.
list(APPEND scenarios_tests test/pan_tilt_footage_test.cpp)
# The loop on other frame sources: record and replay bit for bit, footage not scored.
list(APPEND scenarios_tests test/pan_tilt_sources_test.cpp)
# A rig that is only calibrated (no truth.yaml): pan-tilt on a recording and on images, sim refused.
list(APPEND scenarios_tests test/calibrated_rig_test.cpp)
# Guard of the headline figures: the shipped filter replayed on each path's synthetic measurements.
list(APPEND scenarios_tests test/pan_tilt_headline_test.cpp)
list(APPEND scenarios_tests test/pan_tilt_faults_test.cpp)
# Live mode: paced footage with a slow frame counts the frames missed; unpaced footage runs them all.
list(APPEND scenarios_tests test/pan_tilt_live_test.cpp)
