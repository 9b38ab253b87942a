# rt_core: one suite per source file (tests mirror sources). All deterministic (lockstep).
foreach(suite velocity_filter force_position hunt_crossley friction_cone proxy_intake proxy_blend staleness passivity safety
              joint_angles motor_command latency_histogram rt_thread rt_config tick rt_loop)
  fissure_add_test(rt_core_${suite}_test SOURCES ${suite}_test.cpp LIBS fissure_rt_core)
endforeach()
