# Pan-tilt tracking's live view (the camera image, target, prediction and error), and the footage
# tracker's (camera image, search window, detection, prediction, live status).
list(APPEND viz_sources src/pan_tilt_display.cpp src/footage_display.cpp)
