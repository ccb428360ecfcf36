# Mobile-capture robot ([K], SPEC §4): pan/tilt DH kinematics + IK, differential-drive base with wheel PID,
# ground-plane localisation from one image (exact back-projection and [K]'s angle per pixel).
list(APPEND robots_sources src/mobile_pan_tilt.cpp src/differential_drive.cpp src/mobile_ground_localization.cpp)
list(APPEND robots_tests test/mobile_pan_tilt_test.cpp test/differential_drive_test.cpp
     test/mobile_ground_localization_test.cpp)
