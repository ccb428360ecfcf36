# Pan-tilt tracking's live view (the camera image, target, prediction and error).
list(APPEND viz_sources src/pan_tilt_display.cpp)
