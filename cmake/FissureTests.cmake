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

# One precompiled header for every test executable (CI build time): each suite is a single
# translation unit, so a per-target PCH would cost more than it saves; instead they all reuse
# (REUSE_FROM) the PCH of this object library, compiled with the same warning and sanitizer
# flags. Only third-party and standard headers go in — never our own — and gmock stays out
# (two suites use it; it doubles the PCH that every suite has to load). GCC checks the PCH's
# flags and -Winvalid-pch + -Werror turns a mismatch into an error, never a silent slowdown.
# On in every preset (-DFISSURE_PCH=ON); off by default, see the top-level CMakeLists.txt.
if(FISSURE_PCH)
  file(CONFIGURE OUTPUT ${CMAKE_BINARY_DIR}/fissure_test_pch.cpp
    CONTENT "// anchor for the tests' shared precompiled header\n")
  add_library(fissure_test_pch OBJECT ${CMAKE_BINARY_DIR}/fissure_test_pch.cpp)
  fissure_target_defaults(fissure_test_pch)
  target_link_libraries(fissure_test_pch PRIVATE Eigen3::Eigen GTest::gtest_main)
  target_precompile_headers(fissure_test_pch PRIVATE
    <gtest/gtest.h> <Eigen/Core>
    <algorithm> <array> <atomic> <cmath> <cstdint> <cstdio> <cstdlib> <limits> <memory>
    <random> <string> <thread> <vector>)
endif()

# `cmake --build ... --target fissure_tests_threading` builds just the suites labelled
# "threading" (the ThreadSanitizer stage runs only those).
add_custom_target(fissure_tests_threading)

# fissure_add_test(<name> SOURCES ... [LIBS ...] [LABELS ...])
# One executable per module source it mirrors. A suite is labelled "unit", or the one label
# given (e.g. "threading" for the suites run again under ThreadSanitizer in CI).
function(fissure_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  fissure_target_defaults(${name})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main GTest::gmock)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  if(FISSURE_PCH)
    target_precompile_headers(${name} REUSE_FROM fissure_test_pch)
  endif()
  # One label per suite: CMake 3.25's gtest_discover_tests flattens a ;-list in PROPERTIES.
  set(labels unit)
  if(ARG_LABELS)
    list(GET ARG_LABELS 0 labels)
  endif()
  if(labels STREQUAL "threading")
    add_dependencies(fissure_tests_threading ${name})
  endif()
  # Discovery runs the binary with --gtest_list_tests when ctest starts; under qemu-aarch64 or
  # a sanitizer on a loaded 2-core CI box that can take longer than CMake's 5 s default.
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS "${labels}"
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
endfunction()
