# Mobile-capture robot ([K], SPEC §4): pan/tilt DH kinematics + IK, differential-drive base with wheel PID.
list(APPEND robots_sources src/mobile_pan_tilt.cpp src/differential_drive.cpp)
list(APPEND robots_tests test/mobile_pan_tilt_test.cpp test/differential_drive_test.cpp)
