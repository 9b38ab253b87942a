# Issue 24's tissue validations on coarse meshes (the fine ones and the timings are in
# `fissure bench tissue`): each test mirrors its stage in eval/src/tissue_*.cpp.
fissure_add_test(eval_tissue_cube_test SOURCES tissue_cube_test.cpp LIBS fissure_eval)
fissure_add_test(eval_tissue_punch_test SOURCES tissue_punch_test.cpp LIBS fissure_eval)
fissure_add_test(eval_tissue_cantilever_test SOURCES tissue_cantilever_test.cpp LIBS fissure_eval)
fissure_add_test(eval_tissue_step_cost_test SOURCES tissue_step_cost_test.cpp LIBS fissure_eval)
fissure_add_test(eval_tissue_vessel_test SOURCES tissue_vessel_test.cpp LIBS fissure_eval)
