# Device recordings: the file format, RecordingDevice in front of SimFalcon, ReplayDevice.
fissure_add_test(falcon_hw_device_recording_test SOURCES device_recording_test.cpp allocation_counter.cpp LIBS fissure_falcon_hw)
