# falcon_hw USB part: packet codec, stream parser (incl. the 10^6-stream fuzz),
# FTDI transport helpers, the fake device, and the whole driver run against the fake.
fissure_add_test(falcon_hw_falcon_packet_test SOURCES falcon_packet_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_falcon_stream_parser_test SOURCES falcon_stream_parser_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_usb_transport_test SOURCES usb_transport_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_fake_falcon_transport_test SOURCES fake_falcon_transport_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_falcon_usb_driver_test SOURCES falcon_usb_driver_test.cpp LIBS fissure_falcon_hw)
fissure_add_test(falcon_hw_firmware_image_test SOURCES firmware_image_test.cpp LIBS fissure_falcon_hw)

# The CLI without hardware: one clear line, exit ≠ 0 (skips itself if a Falcon is attached).
if(NOT FISSURE_CORE_ONLY AND TARGET fissure)
  add_test(NAME falcon_hw.device_probe_without_falcon
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/device_probe_without_falcon_test.sh $<TARGET_FILE:fissure>)
  set_tests_properties(falcon_hw.device_probe_without_falcon PROPERTIES LABELS "unit" SKIP_RETURN_CODE 77)
endif()

# Optional libFuzzer target for the stream parser (clang only, not built by default):
#   cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DFISSURE_FUZZ=ON
#   cmake --build build-fuzz --target falcon_stream_parser_fuzzer && build-fuzz/tests/falcon_stream_parser_fuzzer -runs=1000000
option(FISSURE_FUZZ "Build libFuzzer targets (clang)" OFF)
if(FISSURE_FUZZ AND CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  # The parser's sources are compiled into the fuzzer so they get its coverage instrumentation.
  add_executable(falcon_stream_parser_fuzzer EXCLUDE_FROM_ALL falcon_stream_parser_fuzzer.cpp
    ${PROJECT_SOURCE_DIR}/falcon_hw/src/falcon_stream_parser.cpp ${PROJECT_SOURCE_DIR}/falcon_hw/src/falcon_packet.cpp)
  fissure_target_defaults(falcon_stream_parser_fuzzer)
  target_include_directories(falcon_stream_parser_fuzzer PRIVATE ${PROJECT_SOURCE_DIR}/falcon_hw/include)
  target_link_libraries(falcon_stream_parser_fuzzer PRIVATE fissure_shared)
  target_compile_options(falcon_stream_parser_fuzzer PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_options(falcon_stream_parser_fuzzer PRIVATE -fsanitize=fuzzer,address,undefined)
  set_target_properties(falcon_stream_parser_fuzzer PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
endif()
