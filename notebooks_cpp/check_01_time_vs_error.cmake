# Runs notebook 01 on a four-row table whose front is known: runs a (1 ms, 0.4) and c (2 ms, 0.1)
# are on it; b (3 ms, 0.2) is dominated by c; d failed and is ignored. Runs a and c carry small
# EXR images (made with oiiotool), so the image strip is drawn too.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/img")
foreach(name ref a_out a_err c_out c_err)
    if(name STREQUAL "ref")
        set(value 0.8)
    elseif(name MATCHES "_out$")
        set(value 0.6)
    else()
        set(value 0.1)
    endif()
    execute_process(COMMAND "${OIIOTOOL}" --create 32x24 1 --fill:color=${value} 0,0,32,24 -d float
                            -o "${WORK}/img/${name}.exr" RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "oiiotool could not make test images")
    endif()
endforeach()
set(i "${WORK}/img")
file(WRITE "${WORK}/results.jsonl"
"{\"run_id\":\"a\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"t\",\"extract.cpu_ms\":1,\"rms_deviation\":0.4,\"image.technique\":\"${i}/a_out.exr\",\"image.reference\":\"${i}/ref.exr\",\"image.error\":\"${i}/a_err.exr\"}
{\"run_id\":\"b\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"t\",\"extract.cpu_ms\":3,\"rms_deviation\":0.2}
{\"run_id\":\"c\",\"status\":\"ok\",\"scene\":\"room\",\"technique\":\"u\",\"extract.cpu_ms\":2,\"rms_deviation\":0.1,\"image.technique\":\"${i}/c_out.exr\",\"image.reference\":\"${i}/ref.exr\",\"image.error\":\"${i}/c_err.exr\"}
{\"run_id\":\"d\",\"status\":\"failed\",\"scene\":\"room\",\"technique\":\"t\"}
")
include(${CMAKE_CURRENT_LIST_DIR}/notebook_check.cmake)
set(expected "### room: 2 of 3 runs on the front

| run | technique | extract.cpu_ms | rms_deviation |
|---|---|---|---|
| a | t | 1 | 0.4 |
| c | u | 2 | 0.1 |
")
check_notebook("${expected}" pareto_room.png pareto_room.pdf strip_room.png strip_room.pdf)
