# Runs notebook 02 on a table whose answer is known: the baseline's ladder p1 (error 0.4, 10 ms),
# p2 (0.2, 40 ms), p3 (0.1, 160 ms); run x (0.15, 4 ms) is matched by p3 (40x), y (0.3, 20 ms) by
# p2 (2x), w has two frames (0.2, 8 ms and 0.4, 12 ms: means 0.3, 10 ms) and is matched by p2
# (4x), z (0.05, 1 ms) is more accurate than every baseline run (> 160x); a failed run is
# ignored.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"p1\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"path_traced\",\"technique_ms\":10,\"indirect.rmse\":0.4}
{\"run_id\":\"p2\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"path_traced\",\"technique_ms\":40,\"indirect.rmse\":0.2}
{\"run_id\":\"p3\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"path_traced\",\"technique_ms\":160,\"indirect.rmse\":0.1}
{\"run_id\":\"x\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"cascades\",\"technique_ms\":4,\"indirect.rmse\":0.15}
{\"run_id\":\"y\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"cascades\",\"technique_ms\":20,\"indirect.rmse\":0.3}
{\"run_id\":\"w\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"cascades\",\"technique_ms\":8,\"indirect.rmse\":0.2}
{\"run_id\":\"w\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"cascades\",\"technique_ms\":12,\"indirect.rmse\":0.4}
{\"run_id\":\"z\",\"status\":\"ok\",\"scene\":\"town\",\"technique\":\"svo\",\"technique_ms\":1,\"indirect.rmse\":0.05}
{\"run_id\":\"f\",\"status\":\"failed\",\"scene\":\"town\",\"technique\":\"svo\"}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "| w | cascades | 0.3 | 10 | p2 (0.2) | 40 | 4 |
| x | cascades | 0.15 | 4 | p3 (0.1) | 160 | 40 |
| y | cascades | 0.3 | 20 | p2 (0.2) | 40 | 2 |
| z | svo | 0.05 | 1 | none as accurate (best p3: 0.1) | > 160 | > 160 |
")
check_notebook("${expected}" speedup_town.png speedup_town.pdf)
