# Dart ([L] §VI): the measurement-level dart experiment (generated detections of thrown darts,
# the viewline tracker's consistency, gates, asynchronous and late data, single-camera start):
# config (the one YAML reader), world (flights and detections), loop (experiments A-E), metrics;
# footage: the tracker on the marker detected in each camera's footage (no truth, one session).
list(APPEND scenarios_sources dart/config.cpp dart/world.cpp dart/loop.cpp dart/metrics.cpp dart/recording.cpp
     dart/footage.cpp)
list(APPEND scenarios_tests test/dart_recording_test.cpp test/dart_footage_test.cpp)
# Unit and meaning of every key its config reader reads (docs/config_reference.md is generated from it).
list(APPEND scenarios_sources dart/config_keys.cpp)
