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
execute_process(COMMAND "${NOTEBOOK}" "${WORK}" "${WORK}/out" OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "notebook exited with ${rc}:\n${out}")
endif()
set(expected "| cascades | 2 | 0.2 | 0.4 | the cones |
| svo | 1 | 0.5 | 0.1 | the voxels |
")
string(FIND "${out}" "${expected}" at)
if(at EQUAL -1)
    message(FATAL_ERROR "unexpected notebook output:\n${out}\nexpected to contain:\n${expected}")
endif()
if(out MATCHES "path_traced")
    message(FATAL_ERROR "a row without the split was not left out:\n${out}")
endif()
foreach(f split_box.png split_box.pdf)
    if(NOT EXISTS "${WORK}/out/${f}")
        message(FATAL_ERROR "the notebook did not write ${f}")
    endif()
    file(SIZE "${WORK}/out/${f}" size)
    if(size LESS 1000)
        message(FATAL_ERROR "${f} is only ${size} bytes")
    endif()
endforeach()
