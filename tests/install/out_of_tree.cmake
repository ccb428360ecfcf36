# Installs viewline from BUILD_DIR into a temporary prefix, configures and builds the tutorial's
# out-of-tree project against it with find_package, and runs it.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -P out_of_tree.cmake
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT ${v})
    message(FATAL_ERROR "out_of_tree.cmake: ${v} is not set")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(f lib/cmake/viewline/viewlineConfig.cmake lib/cmake/viewline/viewlineConfigVersion.cmake
          include/viewline/tracking/tracker.h share/viewline/config/ball_catching.yaml bin/ball_catching)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tutorials/use_in_your_project -B ${WORK_DIR}/project
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/project)
run(${WORK_DIR}/project/two_cameras)
message(STATUS "two_cameras: ${last_output}")
# A component that does not exist is refused by find_package.
file(MAKE_DIRECTORY ${WORK_DIR}/bad)
file(WRITE ${WORK_DIR}/bad/CMakeLists.txt
  "cmake_minimum_required(VERSION 3.16)\nproject(bad LANGUAGES CXX)\nfind_package(viewline 0.2 REQUIRED COMPONENTS nosuchmodule)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/bad -B ${WORK_DIR}/bad/build -DCMAKE_PREFIX_PATH=${prefix}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "nosuchmodule")
  message(FATAL_ERROR "find_package accepted a missing component:\n${out}\n${err}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
