# Runs notebook 05 on a table whose answer is known: on scene "box", cascades has two frames
# (voxel 0.1 / cone 0.3 and 0.3 / 0.5: means 0.2 and 0.4, the cones dominate) and svo one row
# whose voxels dominate (0.5 / 0.1); a row without the split and a failed run are ignored.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"c\",\"status\":\"ok\",\"scene\":\"box\",\"technique\":\"cascades\",\"split.voxel_rmse\":0.1,\"split.cone_rmse\":0.3}
{\"run_id\":\"c\",\"status\":\"ok\",\"scene\":\"box\",\"technique\":\"cascades\",\"split.voxel_rmse\":0.3,\"split.cone_rmse\":0.5}
{\"run_id\":\"s\",\"status\":\"ok\",\"scene\":\"box\",\"technique\":\"svo\",\"split.voxel_rmse\":0.5,\"split.cone_rmse\":0.1}
{\"run_id\":\"p\",\"status\":\"ok\",\"scene\":\"box\",\"technique\":\"path_traced\",\"indirect.rmse\":0.2}
{\"run_id\":\"f\",\"status\":\"failed\",\"scene\":\"box\",\"technique\":\"svo\"}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "| cascades | 2 | 0.2 | 0.4 | the cones |
| svo | 1 | 0.5 | 0.1 | the voxels |
")
check_notebook("${expected}" split_box.png split_box.pdf)
if(NOTEBOOK_OUTPUT MATCHES "path_traced")
    message(FATAL_ERROR "a row without the split was not left out:\n${NOTEBOOK_OUTPUT}")
endif()
