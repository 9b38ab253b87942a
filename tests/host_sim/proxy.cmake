# Contact proxy builder: checked through rt_core's own proxy evaluation.
fissure_add_test(host_sim_proxy_builder_test
  SOURCES proxy_builder_test.cpp ${CMAKE_CURRENT_SOURCE_DIR}/../falcon_hw/allocation_counter.cpp
  LIBS fissure_host_sim fissure_rt_core)
# The builder's model for a scene (host_sim/proxy_model.cpp).
fissure_add_test(host_sim_proxy_model_test SOURCES proxy_model_test.cpp LIBS fissure_host_sim)
