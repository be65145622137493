include_guard()
include(RtlabTesting)

# rtlab_add_family(<name> SOURCES ... [LIBS ...] [TESTS ...] [TEST_LIBS ...])
#
# Declares one technique family. Call it from framework/families/<name>/CMakeLists.txt; the folder
# must match <name>. It builds a static library of the family's runtime (its passes, metrics and
# report columns, experiment/family.h), records the family in the global property RTLAB_FAMILIES
# (from which framework/families/CMakeLists.txt generates the registration file), and builds the
# family's tests (TESTS) as a ctest executable family_<name>_test.
function(rtlab_add_family name)
    cmake_parse_arguments(_f "" "" "SOURCES;LIBS;TESTS;TEST_LIBS" ${ARGN})
    get_filename_component(_folder "${CMAKE_CURRENT_SOURCE_DIR}" NAME)
    if(NOT _folder STREQUAL name)
        message(FATAL_ERROR "rtlab_add_family(${name}) must be called from framework/families/${name}/, "
                            "not from ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
    if(NOT name MATCHES "^[a-z][a-z0-9_]*$")
        message(FATAL_ERROR "family name '${name}' must be snake_case ([a-z][a-z0-9_]*)")
    endif()
    set(_target rtlab_family_${name})
    add_library(${_target} STATIC ${_f_SOURCES})
    target_include_directories(${_target} PUBLIC ${PROJECT_SOURCE_DIR}/framework)
    target_link_libraries(${_target} PUBLIC rtlab_experiment rtlab_pipeline rtlab_plugin
                                     PRIVATE rtlab_warnings ${_f_LIBS})
    set_property(GLOBAL APPEND PROPERTY RTLAB_FAMILIES "${name}")
    set_property(GLOBAL APPEND PROPERTY RTLAB_FAMILY_TARGETS ${_target})
    if(_f_TESTS)
        rtlab_add_test(family_${name}_test SOURCES ${_f_TESTS}
            LIBS ${_target} ${_f_LIBS} ${_f_TEST_LIBS} LABELS "framework;family")
    endif()
endfunction()
