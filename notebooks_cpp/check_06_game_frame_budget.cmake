# Runs notebook 06 on a table whose answer is known: run g (gtao) has two frames: gbuffer 2 ms GPU
# in both, gtao 4 and 6 ms GPU, compose 1 ms CPU only in the first (culled in the second): means
# 2, 5 and 0.5 ms (their sum 7.5), frame wall time (7.5 + 8.5) / 2 = 8, RMSE (0.1 + 0.2) / 2; run l
# (lsao) has one frame where lsao costs 9 ms (sum 11, wall time 12). A measurement pass (reference)
# is not in frame_passes and is not counted.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"g\",\"status\":\"ok\",\"technique\":\"gtao\",\"frame_passes\":\"gbuffer;gtao;compose\",\"gbuffer.gpu_ms\":2,\"gtao.gpu_ms\":4,\"compose.cpu_ms\":1,\"reference.cpu_ms\":500,\"frame.gpu_ms\":7,\"frame.cpu_ms\":7.5,\"frame.rmse\":0.1}
{\"run_id\":\"g\",\"status\":\"ok\",\"technique\":\"gtao\",\"frame_passes\":\"gbuffer;gtao;compose\",\"gbuffer.gpu_ms\":2,\"gtao.gpu_ms\":6,\"frame.gpu_ms\":8,\"frame.cpu_ms\":8.5,\"frame.rmse\":0.2}
{\"run_id\":\"l\",\"status\":\"ok\",\"technique\":\"lsao\",\"frame_passes\":\"gbuffer;lsao\",\"gbuffer.gpu_ms\":2,\"lsao.gpu_ms\":9,\"frame.gpu_ms\":11,\"frame.cpu_ms\":12,\"frame.rmse\":0.3}
{\"run_id\":\"x\",\"status\":\"failed\",\"technique\":\"lsao\"}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "| g | gtao | 2 | 8 | 7.5 | 0.15 | gtao (5 ms) |
| l | lsao | 1 | 12 | 11 | 0.3 | lsao (9 ms) |
")
check_notebook("${expected}" budget.png budget.pdf)
