# Stage 2 of the thin-body collision (host_sim/src/thin_body/node_sweep.cpp), tested through the
# pipeline's internal header (thin_body/collision_state.hpp) against a brute-force sweep.
fissure_add_test(host_sim_node_sweep_test SOURCES node_sweep_test.cpp LIBS fissure_host_sim)
target_include_directories(host_sim_node_sweep_test PRIVATE ${CMAKE_SOURCE_DIR}/host_sim/src)
