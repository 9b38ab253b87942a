# Hold jitter of the paired collision (issue 5): a held soft node's friction / side memory
# (host_sim/src/thin_body/enforced_displacement.cpp) and the bench's hold cells end to end.
fissure_add_test(host_sim_enforced_displacement_test SOURCES enforced_displacement_test.cpp LIBS fissure_host_sim)
