# The host half of a session (app/session_host.cpp): sweep or re-seat by the device position
# epoch. Lives here because host_sim's test directory includes every *.cmake (tests/app does not).
fissure_add_test(app_session_host_test
  SOURCES ${CMAKE_SOURCE_DIR}/tests/app/session_host_test.cpp
          ${CMAKE_SOURCE_DIR}/app/session_host.cpp
  LIBS fissure_host_sim fissure_rt_core fissure_falcon_hw fissure_shared)
target_include_directories(app_session_host_test PRIVATE ${CMAKE_SOURCE_DIR}/app)
