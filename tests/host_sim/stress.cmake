# `fissure stress --profile ci`: the numerical stability stress harness, every case
# shortened so the whole profile runs in CI in minutes (the full profile runs ≥ 1e6 rt ticks per
# case and is run by hand: fissure stress --profile full). Labelled "stress": the default preset
# runs it; the ASan preset leaves it out (it is a system test, and 5-10x slower there would
# break issue 7's 5-minute budget). The timeout is that budget.
if(TARGET fissure)
  add_test(NAME app.stress_ci
    COMMAND $<TARGET_FILE:fissure> stress --profile ci --json ${CMAKE_BINARY_DIR}/tests/stress-ci.json
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.stress_ci PROPERTIES LABELS "stress" TIMEOUT 300)
endif()
# --jobs: cases in child processes give the in-process rows (app/stress_parallel.cpp).
if(TARGET fissure)
  add_test(NAME app.stress_parallel
    COMMAND bash ${CMAKE_SOURCE_DIR}/tests/app/stress_parallel_test.sh $<TARGET_FILE:fissure>
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(app.stress_parallel PROPERTIES LABELS "stress" TIMEOUT 300)
endif()
