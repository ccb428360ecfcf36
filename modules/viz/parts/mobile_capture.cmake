# Mobile capture: the head camera and a top view of the chase.
list(APPEND viz_sources src/mobile_capture_display.cpp)
