# Scenes, the Bullet world, the method-independent metrics, the `bullet` baseline and the
# host step (everything but the paired/ray algorithm). Suites mirror host_sim/src.
fissure_add_test(host_sim_scene_loader_test SOURCES scene_loader_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_contact_metrics_test SOURCES contact_metrics_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_soft_world_test SOURCES soft_world_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_soft_bending_links_test SOURCES soft_bending_links_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_bullet_collision_test SOURCES bullet_collision_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_host_simulation_test SOURCES host_simulation_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_node_bounds_solver_test SOURCES node_bounds_solver_test.cpp LIBS fissure_host_sim)
