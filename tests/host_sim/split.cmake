# Split deployment: the link bridge between rt_core / the host and the wire, in
# lockstep over a loopback link (tests/app/link_bridge_test.cpp mirrors app/link_bridge.cpp).
# Lives here because host_sim's test directory includes every *.cmake (tests/app does not).
fissure_add_test(app_link_bridge_test
  SOURCES ${CMAKE_SOURCE_DIR}/tests/app/link_bridge_test.cpp
          ${CMAKE_SOURCE_DIR}/app/link_bridge.cpp
          ${CMAKE_SOURCE_DIR}/app/session_host.cpp
  LIBS fissure_host_sim fissure_rt_core fissure_falcon_hw fissure_shared)
target_include_directories(app_link_bridge_test PRIVATE ${CMAKE_SOURCE_DIR}/app)

# Two processes over real UDP on 127.0.0.1 (bounded: ~5 s, every wait has a timeout).
if(TARGET fissure)
  add_test(NAME app.split_udp_two_processes
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/split_udp_test.sh $<TARGET_FILE:fissure>
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.split_udp_two_processes PROPERTIES LABELS "unit" TIMEOUT 90)
endif()
# Transport errors (one line, exit codes) and a 1 s `fissure hil latency` smoke run per transport.
if(TARGET fissure)
  add_test(NAME app.split_cli
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/split_cli_test.sh $<TARGET_FILE:fissure>
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.split_cli PROPERTIES LABELS "unit" TIMEOUT 180)
endif()
