# SimFalcon, the device twin CI runs against, and the scripted hand that holds its grip.
fissure_add_test(falcon_hw_hand_script_player_test SOURCES hand_script_player_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_sim_falcon_test SOURCES sim_falcon_test.cpp allocation_counter.cpp LIBS fissure_falcon_hw)
