# Ball catching: one window per camera (image, detection, estimate, predicted crossing, hole).
list(APPEND viz_sources src/ball_catching_display.cpp)
