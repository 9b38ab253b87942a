# Wire codec and transports (issue 6, "Transports"). One suite per source it mirrors.
foreach(suite crc32c wire_codec wire_reassembler wire_handshake wire_link frame_carrier udp_carrier
        socketcan_carrier fault_injection wire_allocation)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${suite}_test.cpp)
    fissure_add_test(shared_${suite}_test SOURCES ${suite}_test.cpp LIBS fissure_shared)
  endif()
endforeach()
