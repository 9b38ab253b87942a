# Two processes over real UDP on 127.0.0.1 (bounded: ~5 s, every wait has a timeout). Its ports come
# from its PID, as rt_box.split_session_udp's and app.split_cli's do: the three take turns
# (RESOURCE_LOCK) so that two started together never pick the same one.
if(TARGET fissure)
  add_test(NAME app.split_udp_two_processes
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/split_udp_test.sh $<TARGET_FILE:fissure>
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.split_udp_two_processes PROPERTIES LABELS "unit" TIMEOUT 180 RESOURCE_LOCK loopback_udp_ports)
endif()
# Transport errors (one line, exit codes) and a 1 s `fissure hil latency` smoke run per transport.
if(TARGET fissure)
  add_test(NAME app.split_cli
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/split_cli_test.sh $<TARGET_FILE:fissure>
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.split_cli PROPERTIES LABELS "unit" TIMEOUT 180 RESOURCE_LOCK loopback_udp_ports)
endif()
