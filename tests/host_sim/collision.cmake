# Thin-body collision (paired / ray) and its tool model. Suites mirror host_sim/src files.
fissure_add_test(host_sim_thin_tool_test SOURCES thin_tool_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_pair_exclusion_test SOURCES pair_exclusion_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_rim_projection_test SOURCES rim_projection_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_solver_projection_test SOURCES solver_projection_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_paired_collision_test SOURCES paired_collision_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_ray_collision_test SOURCES ray_collision_test.cpp LIBS fissure_host_sim)
