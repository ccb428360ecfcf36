# Dart ([L] §VI): the measurement-level dart experiment (generated detections of thrown darts,
# the viewline tracker's consistency, gates, asynchronous and late data, single-camera start):
# config (the one YAML reader), world (flights and detections), loop (experiments A-E), metrics.
list(APPEND scenarios_sources dart/config.cpp dart/world.cpp dart/loop.cpp dart/metrics.cpp)
