# Pan-tilt tracking ([T]): PTU interface + limits, vpPtu46 kinematics, simulated
# FLIR PTU-D46-17.5, hardware back ends (compiled in only where ViSP has their SDKs).
list(APPEND robots_sources
  src/pan_tilt_unit.cpp
  src/pan_tilt_kinematics.cpp
  src/simulated_pan_tilt.cpp
  src/pan_tilt_hardware.cpp
  src/ptu_link.cpp
  src/flir_ptu_protocol.cpp
  src/flir_ptu.cpp
  src/ptu_emulator.cpp)
list(APPEND robots_tests test/pan_tilt_unit_test.cpp test/flir_ptu_test.cpp)
