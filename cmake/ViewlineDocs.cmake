# The API reference: Doxygen over the public headers of every module (modules/<m>/include).
#   cmake --build build --target api_docs    -> build/docs/api/index.html
#   ctest -R docs.api_reference              -> fails on any Doxygen warning (an undocumented
#                                               public declaration, a broken reference); the
#                                               target prints the same warnings but still builds
# The HTML installs with the package (component api_docs) once it has been built.
find_package(Doxygen QUIET)

set(VIEWLINE_DOCS_OUTPUT_DIR ${PROJECT_BINARY_DIR}/docs)
get_property(_viewline_doc_modules GLOBAL PROPERTY VIEWLINE_MODULES)
set(VIEWLINE_DOCS_INPUT "")
foreach(m IN LISTS _viewline_doc_modules)
  string(APPEND VIEWLINE_DOCS_INPUT " \\\n                         ${PROJECT_SOURCE_DIR}/modules/${m}/include")
endforeach()
set(VIEWLINE_DOCS_STRIP "")
foreach(m IN LISTS _viewline_doc_modules)
  string(APPEND VIEWLINE_DOCS_STRIP " ${PROJECT_SOURCE_DIR}/modules/${m}/include")
endforeach()
set(VIEWLINE_DOXYFILE ${VIEWLINE_DOCS_OUTPUT_DIR}/Doxyfile)
configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${VIEWLINE_DOXYFILE} @ONLY)
# The target writes the HTML even while warnings remain (they are printed); the test is the gate,
# and it writes its HTML to a folder of its own, so the installed reference is only ever what
# api_docs built.
set(VIEWLINE_DOXYFILE_HTML ${VIEWLINE_DOCS_OUTPUT_DIR}/Doxyfile.html)
file(WRITE ${VIEWLINE_DOXYFILE_HTML} "@INCLUDE = \"${VIEWLINE_DOXYFILE}\"\nWARN_AS_ERROR = NO\n")
set(VIEWLINE_DOXYFILE_CHECK ${VIEWLINE_DOCS_OUTPUT_DIR}/Doxyfile.check)
file(WRITE ${VIEWLINE_DOXYFILE_CHECK}
  "@INCLUDE = \"${VIEWLINE_DOXYFILE}\"\nOUTPUT_DIRECTORY = \"${VIEWLINE_DOCS_OUTPUT_DIR}/check\"\n")

if(DOXYGEN_FOUND)
  add_custom_target(api_docs
    COMMAND ${CMAKE_COMMAND} -E make_directory ${VIEWLINE_DOCS_OUTPUT_DIR}
    COMMAND Doxygen::doxygen ${VIEWLINE_DOXYFILE_HTML}
    WORKING_DIRECTORY ${VIEWLINE_DOCS_OUTPUT_DIR}
    COMMENT "API reference (Doxygen) -> ${VIEWLINE_DOCS_OUTPUT_DIR}/api/index.html"
    VERBATIM)
else()
  add_custom_target(api_docs
    COMMAND ${CMAKE_COMMAND} -E echo "api_docs: doxygen not found (scripts/install-deps installs it)"
    COMMAND ${CMAKE_COMMAND} -E false
    VERBATIM)
endif()

if(VIEWLINE_BUILD_TESTS)
  if(DOXYGEN_FOUND)
    # WARN_AS_ERROR = FAIL_ON_WARNINGS: every warning is printed, then the exit status is non-zero.
    add_test(NAME docs.api_reference COMMAND Doxygen::doxygen ${VIEWLINE_DOXYFILE_CHECK}
      WORKING_DIRECTORY ${VIEWLINE_DOCS_OUTPUT_DIR})
    set_tests_properties(docs.api_reference PROPERTIES LABELS docs TIMEOUT 600)
  else()
    # Skipped, not passed: the reference was not checked on this machine.
    add_test(NAME docs.api_reference COMMAND sh -c
      "echo 'docs.api_reference: SKIPPED, doxygen not found (scripts/install-deps installs it)'; exit 77")
    set_tests_properties(docs.api_reference PROPERTIES LABELS docs SKIP_RETURN_CODE 77)
  endif()
endif()

include(GNUInstallDirs)
install(DIRECTORY ${VIEWLINE_DOCS_OUTPUT_DIR}/api/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/api
  COMPONENT api_docs OPTIONAL)

# Every relative link and picture of the Markdown pages names a file inside the repository
# (scripts/check-links), and no page sends the reader outside it.
add_test(NAME docs.links COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/check-links ${PROJECT_SOURCE_DIR})
set_tests_properties(docs.links PROPERTIES LABELS docs)
