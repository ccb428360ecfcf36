# Regenerates the config reference into OUTPUT and fails, with the diff and the command to
# regenerate, when SOURCE_DIR/docs/config_reference.md differs from it.
#   cmake -DTOOL=<viewline_config_reference> -DSOURCE_DIR=<repo> -DOUTPUT=<file> -P check_current.cmake
execute_process(COMMAND ${TOOL} --config-dir ${SOURCE_DIR}/config --output ${OUTPUT}
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "viewline_config_reference failed (status ${status}): a key table disagrees with its reader (see above)")
endif()
set(committed ${SOURCE_DIR}/docs/config_reference.md)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${committed} ${OUTPUT} RESULT_VARIABLE differs)
if(differs)
  execute_process(COMMAND diff -u ${committed} ${OUTPUT})
  message(FATAL_ERROR "docs/config_reference.md is stale (the diff above: committed -> what the code reads now).\n"
    "Regenerate it from the repository's top folder:\n"
    "  build/bin/viewline_config_reference --config-dir config --output docs/config_reference.md")
endif()
message(STATUS "docs/config_reference.md is current")
