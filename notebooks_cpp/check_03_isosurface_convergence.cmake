# Runs notebook 03 on a table whose orders are known: on scene "ball", technique a's error is
# 2 h^2 and b's is 3 h at h = 0.1, 0.05, 0.025 (orders 2 and 1 exactly); a midpoint-vertex
# configuration of a (0.5 h) is its own line; a run on one grid has no order; a failed run and a
# row without cell_size are ignored.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"a1\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"a\",\"cell_size\":0.1,\"chamfer.mean\":0.02}
{\"run_id\":\"a2\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"a\",\"cell_size\":0.05,\"chamfer.mean\":0.005}
{\"run_id\":\"a3\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"a\",\"cell_size\":0.025,\"chamfer.mean\":0.00125}
{\"run_id\":\"b1\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"b\",\"cell_size\":0.1,\"chamfer.mean\":0.3}
{\"run_id\":\"b2\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"b\",\"cell_size\":0.05,\"chamfer.mean\":0.15}
{\"run_id\":\"b3\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"b\",\"cell_size\":0.025,\"chamfer.mean\":0.075}
{\"run_id\":\"m1\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"a\",\"param.vertex_placement\":\"midpoint\",\"cell_size\":0.1,\"chamfer.mean\":0.05}
{\"run_id\":\"m2\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"a\",\"param.vertex_placement\":\"midpoint\",\"cell_size\":0.05,\"chamfer.mean\":0.025}
{\"run_id\":\"c1\",\"status\":\"ok\",\"scene\":\"ball\",\"technique\":\"c\",\"cell_size\":0.1,\"chamfer.mean\":0.01}
{\"run_id\":\"f\",\"status\":\"failed\",\"scene\":\"ball\",\"technique\":\"b\",\"cell_size\":0.0125}
{\"run_id\":\"ao\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"gtao\",\"ao.rmse\":0.1}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "| ball | a | 3 | 2.00 |
| ball | a vertex_placement=midpoint | 2 | 1.00 |
| ball | b | 3 | 1.00 |
| ball | c | 1 | one grid: none |
")
check_notebook("${expected}" convergence_ball.png convergence_ball.pdf)
