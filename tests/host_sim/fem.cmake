# Tissue FEM (issue 24): SI materials mapped onto Bullet's deformable-world forces, structured
# tetrahedral boxes, and the deformable world with fixed nodes and reaction forces.
fissure_add_test(host_sim_fem_material_test SOURCES fem_material_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_tet_box_test SOURCES tet_box_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_fem_body_test SOURCES fem_body_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_fem_world_test SOURCES fem_world_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_soft_world_fem_test SOURCES soft_world_fem_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_fem_smoothed_strain_force_test SOURCES fem_smoothed_strain_force_test.cpp LIBS fissure_host_sim)
target_include_directories(host_sim_fem_smoothed_strain_force_test PRIVATE ${CMAKE_SOURCE_DIR}/host_sim/src)
