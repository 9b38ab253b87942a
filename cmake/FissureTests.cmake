# GoogleTest, either Debian's installed build or (for cross builds, where the host's
# libgtest is the wrong architecture) compiled from Debian's /usr/src/googletest.
if(FISSURE_GTEST_FROM_SOURCE)
  set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
  add_subdirectory(/usr/src/googletest ${CMAKE_BINARY_DIR}/_googletest EXCLUDE_FROM_ALL)
  # googletest ≥ 1.11 defines the GTest:: aliases itself; older trees do not.
  if(NOT TARGET GTest::gtest_main)
    add_library(GTest::gtest_main ALIAS gtest_main)
    add_library(GTest::gmock ALIAS gmock)
  endif()
else()
  find_package(GTest REQUIRED)
endif()
include(GoogleTest)

# fissure_add_test(<name> SOURCES ... [LIBS ...] [LABELS ...])
# One executable per module source it mirrors. A suite is labelled "unit", or the one label
# given (e.g. "threading" for the suites run again under ThreadSanitizer in CI).
function(fissure_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  fissure_target_defaults(${name})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main GTest::gmock)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  # One label per suite: CMake 3.25's gtest_discover_tests flattens a ;-list in PROPERTIES.
  set(labels unit)
  if(ARG_LABELS)
    list(GET ARG_LABELS 0 labels)
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES LABELS "${labels}"
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
endfunction()
