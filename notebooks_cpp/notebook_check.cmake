# What the notebooks' checks share (cmake -P scripts): run ${NOTEBOOK} on the results table the
# check wrote into ${WORK}, writing its figures to ${WORK}/out, and require that its output
# contains `expected` and that each file named after it is in ${WORK}/out with at least 1000
# bytes. The notebook's output is left in NOTEBOOK_OUTPUT for further checks.
function(check_notebook expected)
    execute_process(COMMAND "${NOTEBOOK}" "${WORK}" "${WORK}/out" OUTPUT_VARIABLE out RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "notebook exited with ${rc}:\n${out}")
    endif()
    string(FIND "${out}" "${expected}" at)
    if(at EQUAL -1)
        message(FATAL_ERROR "unexpected notebook output:\n${out}\nexpected to contain:\n${expected}")
    endif()
    foreach(f IN LISTS ARGN)
        if(NOT EXISTS "${WORK}/out/${f}")
            message(FATAL_ERROR "the notebook did not write ${f}")
        endif()
        file(SIZE "${WORK}/out/${f}" size)
        if(size LESS 1000)
            message(FATAL_ERROR "${f} is only ${size} bytes")
        endif()
    endforeach()
    set(NOTEBOOK_OUTPUT "${out}" PARENT_SCOPE)
endfunction()
