# The independent oracle of the contact metrics (fcl_oracle.hpp): FCL's triangle–convex test on
# the tool's hull shrunk by Bullet. Test support only: nothing under host_sim/ or the product
# links it. FCL comes from Debian's libfcl-dev (toolchain/setup.sh); tests/host_sim is not
# configured by the core-only presets (aarch64, tsan), so they do not need it.
find_package(fcl 0.7 REQUIRED CONFIG)
add_library(fissure_test_fcl_oracle STATIC fcl_oracle.cpp)
fissure_target_defaults(fissure_test_fcl_oracle)
target_include_directories(fissure_test_fcl_oracle PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(fissure_test_fcl_oracle PUBLIC fissure_host_sim PRIVATE fcl)
fissure_add_test(host_sim_fcl_oracle_test SOURCES fcl_oracle_test.cpp LIBS fissure_test_fcl_oracle)
# The suites whose cut-triangle and inside-node checks the oracle confirms (collision.cmake,
# hold_jitter.cmake: defined before this file, file(GLOB) sorts).
target_link_libraries(host_sim_paired_collision_test PRIVATE fissure_test_fcl_oracle)
target_link_libraries(host_sim_hold_jitter_test PRIVATE fissure_test_fcl_oracle)
