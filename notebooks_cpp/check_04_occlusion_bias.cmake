# Runs notebook 04 on a table whose answer is known: technique a has two runs whose error is all
# bias (+0.1 mean signed error, RMSE 0.1, and the same); b has RMSE 0.2 with bias -0.05 (share
# 0.0625, mostly noise); c is biased dark (-0.3, RMSE 0.4: share 0.5625). An isosurface row and a
# failed run are ignored.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"a1\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"a\",\"ao.rmse\":0.1,\"ao.mean_signed_error\":0.1}
{\"run_id\":\"a2\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"a\",\"ao.rmse\":0.1,\"ao.mean_signed_error\":0.1}
{\"run_id\":\"b1\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"b\",\"ao.rmse\":0.2,\"ao.mean_signed_error\":-0.05}
{\"run_id\":\"c1\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"c\",\"ao.rmse\":0.4,\"ao.mean_signed_error\":-0.3}
{\"run_id\":\"f\",\"status\":\"failed\",\"scene\":\"room\",\"technique\":\"c\"}
{\"run_id\":\"m\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"marching_cubes\",\"chamfer.mean\":0.01}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "| a | 2 | +0.1000 | 0.1000 | 1.00 | biased bright (misses occlusion) |
| b | 1 | -0.0500 | 0.2000 | 0.06 | mostly noise or local error |
| c | 1 | -0.3000 | 0.4000 | 0.56 | biased dark (over-occludes) |
")
check_notebook("${expected}" bias_room.png bias_room.pdf)
if(NOTEBOOK_OUTPUT MATCHES "### ball")
    message(FATAL_ERROR "the isosurface scene was not left out:\n${NOTEBOOK_OUTPUT}")
endif()
