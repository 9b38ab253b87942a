# Regressions found by `fissure stress` on the host side.
fissure_add_test(host_sim_crossing_path_test SOURCES crossing_path_test.cpp LIBS fissure_host_sim)
