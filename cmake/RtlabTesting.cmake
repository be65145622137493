include_guard()
# rtlab_add_test(<name> SOURCES ... [LIBS ...] [LABELS ...])
# One GoogleTest executable; its tests are discovered by ctest when ctest runs (not at build time,
# which keeps builds fast). RTLAB_SOURCE_DIR points tests at shaders, scenes and experiments.
function(rtlab_add_test name)
    cmake_parse_arguments(_t "" "" "SOURCES;LIBS;LABELS" ${ARGN})
    add_executable(${name} ${_t_SOURCES})
    target_link_libraries(${name} PRIVATE ${_t_LIBS} GTest::gtest GTest::gmock GTest::gtest_main
                                          rtlab_warnings)
    target_compile_definitions(${name} PRIVATE RTLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 TEST_PREFIX "${name}."
        PROPERTIES LABELS "${_t_LABELS}"
                   ENVIRONMENT "RTLAB_SOURCE_DIR=${PROJECT_SOURCE_DIR};RTLAB_CACHE_DIR=${PROJECT_BINARY_DIR}/cache")
endfunction()
