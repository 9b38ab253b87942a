# Falcon kinematics: encoder mapping, IK / Jacobian / FK, force → motor command.
fissure_add_test(falcon_hw_encoder_mapping_test SOURCES encoder_mapping_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_kinematics_test SOURCES kinematics_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_motor_command_test SOURCES motor_command_test.cpp LIBS fissure_falcon_hw)

# The CLI on top (app/device_kinematics.cpp, eval/src/bench_kinematics.cpp); the script lives with
# the other app tests but is registered here, by the kinematics owner, when the app is built.
if(TARGET fissure)
  add_test(NAME app.device_kinematics
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/device_kinematics_test.sh $<TARGET_FILE:fissure>)
  set_tests_properties(app.device_kinematics PROPERTIES LABELS "unit")
endif()
