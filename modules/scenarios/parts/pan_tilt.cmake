# Pan-tilt tracking ([T], issue 6): the closed loop (screen world, rendering, [T] detection, [T]
# noise, predictive and ViSP baseline controllers, metrics) and its live view, as library code.
list(APPEND scenarios_sources src/pan_tilt_scenario.cpp src/pan_tilt_display.cpp)
