include_guard()
# rtlab_add_test(<name> SOURCES ... [LIBS ...] [LABELS ...])
# One GoogleTest executable; its tests are discovered by ctest when ctest runs (not at build time,
# which keeps builds fast) and named "<name>.<Suite>.<Test>", so `ctest -R <name>` selects them.
# RTLAB_SOURCE_DIR points tests at shaders, scenes and experiments; RTLAB_CACHE_DIR keeps their
# caches inside the build folder.
function(rtlab_add_test name)
    cmake_parse_arguments(_t "" "" "SOURCES;LIBS;LABELS" ${ARGN})
    add_executable(${name} ${_t_SOURCES})
    target_link_libraries(${name} PRIVATE ${_t_LIBS} GTest::gtest GTest::gmock GTest::gtest_main
                                          rtlab_warnings)
    target_compile_definitions(${name} PRIVATE RTLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
                         TEST_PREFIX "${name}." TEST_LIST ${name}_TESTS)
    # Discovery at ctest time flattens list-valued PROPERTIES (only the first label and the first
    # environment entry survive), so labels and environment are set by a file that ctest
    # includes after the discovery's own.
    set(_properties ${CMAKE_CURRENT_BINARY_DIR}/${name}_properties.cmake)
    file(WRITE ${_properties}
        "foreach(_test IN LISTS ${name}_TESTS)\n"
        "    set_tests_properties(\"\${_test}\" PROPERTIES LABELS \"${_t_LABELS}\"\n"
        "        ENVIRONMENT \"RTLAB_SOURCE_DIR=${PROJECT_SOURCE_DIR};"
        "RTLAB_CACHE_DIR=${PROJECT_BINARY_DIR}/cache\")\n"
        "endforeach()\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${_properties})
endfunction()
