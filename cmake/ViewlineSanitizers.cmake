# Sanitizer and fuzzing instrumentation, as one INTERFACE target (no global CMAKE_CXX_FLAGS).
#
#   -DVIEWLINE_SANITIZE=address,undefined   ASan + UBSan (LeakSanitizer comes with ASan on Linux)
#   -DVIEWLINE_SANITIZE=OFF                 (default) no instrumentation
#   -DVIEWLINE_BUILD_FUZZ=ON                libFuzzer targets (clang only): every target also gets
#                                           -fsanitize=fuzzer-no-link (coverage feedback) and the
#                                           fuzz/ executables link the libFuzzer main.
#
# viewline::sanitizers carries the flags; viewline_apply_sanitizers(<dir>) (called once at the end
# of the top-level CMakeLists.txt) adds it to the link libraries of every library and executable
# defined under <dir>, so that modules, tests, apps and benches need no change. UBSan does not
# recover (-fno-sanitize-recover=all): the first report ends the process with a failure, so a
# test cannot pass with a report in its output. scripts/test --sanitize sets the runtime options.

set(VIEWLINE_SANITIZE "OFF" CACHE STRING
    "Sanitizers for every viewline target: OFF, or a -fsanitize= list such as address,undefined")

if(NOT TARGET viewline_sanitizers)
  add_library(viewline_sanitizers INTERFACE)
  add_library(viewline::sanitizers ALIAS viewline_sanitizers)
endif()

set(_viewline_instrumented OFF)
if(VIEWLINE_SANITIZE AND NOT VIEWLINE_SANITIZE STREQUAL "OFF")
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    message(FATAL_ERROR "VIEWLINE_SANITIZE needs g++ or clang++ (got ${CMAKE_CXX_COMPILER_ID})")
  endif()
  target_compile_options(viewline_sanitizers INTERFACE
    -fsanitize=${VIEWLINE_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer -g1)
  target_link_options(viewline_sanitizers INTERFACE -fsanitize=${VIEWLINE_SANITIZE})
  set(_viewline_instrumented ON)
  message(STATUS "viewline: sanitizers ${VIEWLINE_SANITIZE} on every target")
endif()

if(VIEWLINE_BUILD_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "VIEWLINE_BUILD_FUZZ needs clang++ (libFuzzer), e.g. -DCMAKE_CXX_COMPILER=clang++-14; "
                        "the g++ build replays the corpora with a plain driver instead (fuzz/CMakeLists.txt)")
  endif()
  target_compile_options(viewline_sanitizers INTERFACE -fsanitize=fuzzer-no-link)
  set(_viewline_instrumented ON)
endif()

# Adds viewline::sanitizers to every non-imported library/executable defined in `dir` and below.
# Appending to LINK_LIBRARIES (not target_link_libraries) works whatever signature the target's
# own CMakeLists used, and the usage requirements (compile and link options) follow from it.
function(viewline_apply_sanitizers dir)
  if(NOT _viewline_instrumented)
    return()
  endif()
  get_property(targets DIRECTORY "${dir}" PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t ${targets})
    get_target_property(type ${t} TYPE)
    if(type MATCHES "^(STATIC_LIBRARY|SHARED_LIBRARY|MODULE_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$")
      set_property(TARGET ${t} APPEND PROPERTY LINK_LIBRARIES viewline_sanitizers)
    endif()
  endforeach()
  get_property(subdirs DIRECTORY "${dir}" PROPERTY SUBDIRECTORIES)
  foreach(d ${subdirs})
    viewline_apply_sanitizers("${d}")
  endforeach()
endfunction()
