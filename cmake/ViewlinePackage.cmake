# Install rules and the CMake package (find_package(viewline)), and the Debian package (CPack).
# Modules and apps install themselves (cmake/ViewlineModule.cmake); this file adds the export, the
# package config, the default scenarios and rigs, and the .deb.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(VIEWLINE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/viewline)
get_property(VIEWLINE_MODULE_LIST GLOBAL PROPERTY VIEWLINE_MODULES)

# The sanitizer interface (empty unless VIEWLINE_SANITIZE is set) is linked by every target of an
# instrumented build, so it travels with the export set.
if(TARGET viewline_sanitizers)
  set_target_properties(viewline_sanitizers PROPERTIES EXPORT_NAME sanitizers)
  install(TARGETS viewline_sanitizers EXPORT viewlineTargets)
endif()
install(EXPORT viewlineTargets NAMESPACE viewline:: DESTINATION ${VIEWLINE_CMAKE_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/viewlineConfig.cmake.in
  ${PROJECT_BINARY_DIR}/viewlineConfig.cmake INSTALL_DESTINATION ${VIEWLINE_CMAKE_DIR})
# 0.x: a minor release may break the API, so only the same major.minor is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/viewlineConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/viewlineConfig.cmake ${PROJECT_BINARY_DIR}/viewlineConfigVersion.cmake
  DESTINATION ${VIEWLINE_CMAKE_DIR})

# The default scenarios and the rigs they name (config/*.yaml say rig: ../calib/rigs/<rig>).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${CMAKE_INSTALL_DATADIR}/viewline/config)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/calib/rigs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/viewline/calib/rigs)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# Debian package: cpack -G DEB in the build folder writes viewline_<version>_amd64.deb. Its
# dependencies are the Debian packages scripts/install-deps installs for building and running
# (headers included: the package is a development library as much as a set of apps).
set(CPACK_PACKAGE_NAME viewline)
set(CPACK_PACKAGE_VENDOR "viewline developers")
set(CPACK_PACKAGE_CONTACT "viewline developers <viewline@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
  "libvisp-dev (>= 3.5), libopencv-dev (>= 4.6), libopencv-contrib-dev, libeigen3-dev, libboost-dev, libyaml-cpp-dev, nlohmann-json3-dev, libcli11-dev, libapriltag-dev, gnuplot-nox, cyclonedds-dev (>= 0.10)")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
