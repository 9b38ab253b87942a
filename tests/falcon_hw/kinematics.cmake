# Falcon kinematics: encoder mapping, IK / Jacobian / FK, force → motor command.
fissure_add_test(falcon_hw_encoder_mapping_test SOURCES encoder_mapping_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_kinematics_test SOURCES kinematics_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_motor_command_test SOURCES motor_command_test.cpp LIBS fissure_falcon_hw)
