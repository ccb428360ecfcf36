# Helpers that declare a module, a test, a benchmark and an app the same way everywhere.

# Compiler warnings as an INTERFACE target (no global flags).
if(NOT TARGET viewline_warnings)
  add_library(viewline_warnings INTERFACE)
  target_compile_options(viewline_warnings INTERFACE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2>)
  if(VIEWLINE_WARNINGS_AS_ERRORS)
    target_compile_options(viewline_warnings INTERFACE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>)
  endif()
  target_compile_features(viewline_warnings INTERFACE cxx_std_17)
  add_library(viewline::warnings ALIAS viewline_warnings)
  # Static modules list it as a link-only dependency: it must be in the export set too.
  set_target_properties(viewline_warnings PROPERTIES EXPORT_NAME warnings)
  install(TARGETS viewline_warnings EXPORT viewlineTargets)
endif()

include(GNUInstallDirs)

# viewline_add_module(<name> SOURCES a.cpp ... DEPENDS <targets>... [PRIVATE_DEPENDS ...])
# Creates target viewline_<name>, alias viewline::<name>, headers under include/viewline/<name>.
function(viewline_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  set(target viewline_${name})
  # Static unless BUILD_SHARED_LIBS is ON.
  add_library(${target} ${ARG_SOURCES})
  add_library(viewline::${name} ALIAS ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_DEPENDS} PRIVATE viewline::warnings ${ARG_PRIVATE_DEPENDS})
  target_compile_features(${target} PUBLIC cxx_std_17)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON
    EXPORT_NAME ${name} VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  # Installed as viewline::<name> (cmake/ViewlinePackage.cmake writes the package config).
  install(TARGETS ${target} EXPORT viewlineTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY VIEWLINE_MODULES ${name})
endfunction()

# viewline_add_test(<name> SOURCES ... DEPENDS ... [LABELS ...] [TIMEOUT s] [RUN_SERIAL])
# One GoogleTest executable; every TEST() becomes a ctest test.
function(viewline_add_test name)
  if(NOT VIEWLINE_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "RUN_SERIAL" "TIMEOUT" "SOURCES;DEPENDS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  set(serial FALSE)
  if(ARG_RUN_SERIAL)  # tests that time several processes (e.g. DDS nodes): alone on the machine
    set(serial TRUE)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPENDS} GTest::gtest GTest::gtest_main viewline::warnings)
  set_target_properties(${name} PROPERTIES CXX_EXTENSIONS OFF)
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${serial}
    DISCOVERY_TIMEOUT 60)
endfunction()

# viewline_add_bench(<name> SOURCES ... DEPENDS ...)
function(viewline_add_bench name)
  if(NOT VIEWLINE_BUILD_BENCH)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPENDS} benchmark::benchmark viewline::warnings)
  set_target_properties(${name} PROPERTIES CXX_EXTENSIONS OFF RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench)
endfunction()

# viewline_add_app(<name> SOURCES ... DEPENDS ...): executables land in <build>/bin.
function(viewline_add_app name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPENDS} viewline::warnings)
  set_target_properties(${name} PROPERTIES CXX_EXTENSIONS OFF RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin
    INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
  install(TARGETS ${name} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()
