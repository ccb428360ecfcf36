# Third-party packages, all from Debian 12 (scripts/install-deps installs them).
# Each is found once here so that modules only name imported targets.

if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type" FORCE)
endif()

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(VISP 3.5 REQUIRED COMPONENTS visp_core visp_vision visp_detection visp_vs visp_robot visp_io visp_gui)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc calib3d video videoio imgcodecs aruco)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 QUIET CONFIG)
find_package(Boost 1.71 REQUIRED)   # header-only: Boost.Math distributions (chi-square quantiles)
find_package(Threads REQUIRED)

# ViSP's config exports one imported target per module but no include
# directories on them; wrap it into one interface target.
if(NOT TARGET viewline_visp)
  add_library(viewline_visp INTERFACE)
  target_include_directories(viewline_visp SYSTEM INTERFACE ${VISP_INCLUDE_DIRS})
  target_link_libraries(viewline_visp INTERFACE ${VISP_LIBRARIES})
  add_library(viewline::visp ALIAS viewline_visp)
  set_target_properties(viewline_visp PROPERTIES EXPORT_NAME visp)
  install(TARGETS viewline_visp EXPORT viewlineTargets)
endif()

if(NOT TARGET viewline_opencv)
  add_library(viewline_opencv INTERFACE)
  target_include_directories(viewline_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(viewline_opencv INTERFACE ${OpenCV_LIBS})
  add_library(viewline::opencv ALIAS viewline_opencv)
  set_target_properties(viewline_opencv PROPERTIES EXPORT_NAME opencv)
  install(TARGETS viewline_opencv EXPORT viewlineTargets)
endif()

if(NOT TARGET CLI11::CLI11)
  # Debian's libcli11-dev ships the header only on some releases.
  add_library(CLI11::CLI11 INTERFACE IMPORTED)
endif()

if(VIEWLINE_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(VIEWLINE_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
