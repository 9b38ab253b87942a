# Soft-body anchoring ([[soft_body.anchor]]): selection, the ground anchors, and a plate pushing
# a free versus an anchored ball (soft_body_builder.cpp anchor_soft_body, soft_world.cpp).
fissure_add_test(host_sim_soft_body_anchor_test SOURCES soft_body_anchor_test.cpp LIBS fissure_host_sim)
