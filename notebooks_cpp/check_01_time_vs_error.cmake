# Runs notebook 01 on a four-row table whose front is known: runs a (1 ms, 0.4) and c (2 ms, 0.1)
# are on it; b (3 ms, 0.2) is dominated by c; d failed and is ignored.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"a\",\"status\":\"ok\",\"scene\":\"sphere\",\"technique\":\"t\",\"extract.cpu_ms\":1,\"rms_deviation\":0.4}
{\"run_id\":\"b\",\"status\":\"ok\",\"scene\":\"sphere\",\"technique\":\"t\",\"extract.cpu_ms\":3,\"rms_deviation\":0.2}
{\"run_id\":\"c\",\"status\":\"ok\",\"scene\":\"sphere\",\"technique\":\"t\",\"extract.cpu_ms\":2,\"rms_deviation\":0.1}
{\"run_id\":\"d\",\"status\":\"failed\",\"scene\":\"sphere\",\"technique\":\"t\"}
")
execute_process(COMMAND "${NOTEBOOK}" "${WORK}" OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "notebook exited with ${rc}:\n${out}")
endif()
set(expected "### sphere: 2 of 3 runs on the front

| run | technique | extract.cpu_ms | rms_deviation |
|---|---|---|---|
| a | t | 1 | 0.4 |
| c | t | 2 | 0.1 |
")
string(FIND "${out}" "${expected}" at)
if(at EQUAL -1)
    message(FATAL_ERROR "unexpected notebook output:\n${out}\nexpected to contain:\n${expected}")
endif()
message(STATUS "notebook 01 output as expected")
