# Stage 1 of the thin-body collision (host_sim/src/thin_body/broad_phase.cpp), tested through the
# pipeline's internal header (thin_body/collision_state.hpp).
fissure_add_test(host_sim_broad_phase_test SOURCES broad_phase_test.cpp LIBS fissure_host_sim)
target_include_directories(host_sim_broad_phase_test PRIVATE ${CMAKE_SOURCE_DIR}/host_sim/src)
