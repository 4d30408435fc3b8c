# nudge_add_test(<name>
#                SOURCES <file>...            # relative to tests/ (or absolute)
#                [LIBRARIES <target>...]      # GoogleTest and gtest_main are always linked
#                [LABELS <label>...]          # ctest labels of every test case (unit, service, integration)
#                [BINARIES <target>...]       # programs the test runs: built first
#                [TIMEOUT <seconds>])         # per test case
#
# One GoogleTest executable whose test cases ctest discovers after the build. It sees
# NUDGE_SOURCE_DIR (the source tree) and NUDGE_BIN_DIR (where the programs are) as string macros.
include(GoogleTest)

function(nudge_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBRARIES;LABELS;BINARIES" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "nudge_add_test(${name}): no SOURCES")
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARIES} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE NUDGE_SOURCE_DIR="${CMAKE_SOURCE_DIR}"
                                             NUDGE_BIN_DIR="${CMAKE_RUNTIME_OUTPUT_DIRECTORY}")
  if(ARG_BINARIES)
    add_dependencies(${name} ${ARG_BINARIES})
  endif()
  set(properties LABELS "${ARG_LABELS}")
  if(ARG_TIMEOUT)
    list(APPEND properties TIMEOUT ${ARG_TIMEOUT})
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES ${properties})
endfunction()
