# Wire codec and transports. One suite per source it mirrors; the
# fault-injection suite drives the codec, reassembly and link over a damaged loopback.
fissure_add_test(shared_crc32c_test SOURCES crc32c_test.cpp LIBS fissure_shared)
fissure_add_test(shared_wire_codec_test SOURCES wire_codec_test.cpp LIBS fissure_shared)
fissure_add_test(shared_wire_reassembler_test SOURCES wire_reassembler_test.cpp LIBS fissure_shared)
fissure_add_test(shared_wire_handshake_test SOURCES wire_handshake_test.cpp LIBS fissure_shared)
fissure_add_test(shared_wire_link_test SOURCES wire_link_test.cpp LIBS fissure_shared)
fissure_add_test(shared_frame_carrier_test SOURCES frame_carrier_test.cpp LIBS fissure_shared LABELS threading)
fissure_add_test(shared_udp_carrier_test SOURCES udp_carrier_test.cpp LIBS fissure_shared)
fissure_add_test(shared_socketcan_carrier_test SOURCES socketcan_carrier_test.cpp LIBS fissure_shared)
fissure_add_test(shared_fault_injection_test SOURCES fault_injection_test.cpp LIBS fissure_shared)
fissure_add_test(shared_wire_allocation_test SOURCES wire_allocation_test.cpp LIBS fissure_shared)
fissure_add_test(shared_transport_spec_test SOURCES transport_spec_test.cpp LIBS fissure_shared)
