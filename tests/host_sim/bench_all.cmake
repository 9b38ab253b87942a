# The benchmark report: tools/report/make_report.py run on a fixed JSON fixture
# (tests/app/report_fixture/) — every required section, linked PNGs that exist, met/missed marks.
# `fissure bench all` itself takes ~10 minutes and is not a ctest. Debian's python3 (the one with
# python3-matplotlib, as `fissure bench all` uses); the test skips (exit 77) without matplotlib.
find_program(FISSURE_REPORT_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT FISSURE_REPORT_PYTHON)
  find_program(FISSURE_REPORT_PYTHON NAMES python3)
endif()
if(FISSURE_REPORT_PYTHON)
  add_test(NAME app.bench_report
    COMMAND ${FISSURE_REPORT_PYTHON} ${CMAKE_SOURCE_DIR}/tests/app/report_test.py
            ${CMAKE_SOURCE_DIR}/tools/report ${CMAKE_SOURCE_DIR}/tests/app/report_fixture
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.bench_report PROPERTIES LABELS "unit" SKIP_RETURN_CODE 77 TIMEOUT 120)
else()
  message(STATUS "app.bench_report: no python3 found, the report generator test is not registered")
endif()
