# Mesh import (issue 24): OBJ / STL files, closed-surface checks, the box trees that keep
# loading n log n, convex tool meshes from files, and soft bodies from a closed surface mesh.
fissure_add_test(host_sim_mesh_file_test SOURCES mesh_file_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_mesh_checks_test SOURCES mesh_checks_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_mesh_bvh_test SOURCES mesh_bvh_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_tool_mesh_io_test SOURCES tool_mesh_io_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_soft_body_builder_test SOURCES soft_body_builder_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_tet_mesh_file_test SOURCES tet_mesh_file_test.cpp LIBS fissure_host_sim)
fissure_add_test(host_sim_tet_mesh_checks_test SOURCES tet_mesh_checks_test.cpp LIBS fissure_host_sim)
# A real TetGen run in the soft body test when the Debian tetgen is installed (it skips, saying so, otherwise).
find_program(FISSURE_TETGEN tetgen)
if(FISSURE_TETGEN)
  target_compile_definitions(host_sim_soft_body_builder_test PRIVATE FISSURE_TETGEN_EXECUTABLE="${FISSURE_TETGEN}")
endif()
