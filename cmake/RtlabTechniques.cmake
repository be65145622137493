include_guard()
include(RtlabTesting)

# rtlab_add_technique(<name> FAMILY <family> SOURCES ... [SHADERS ...] [TESTS ...] [LIBS ...]
#                     [TEST_LIBS ...])
#
# Declares one technique plugin. Call it from techniques/<family>/<name>/CMakeLists.txt; the folder
# must match <family>/<name>. It builds a static library, records the technique in the global
# property RTLAB_TECHNIQUES (from which techniques/CMakeLists.txt generates the registration file),
# and builds the technique's unit tests (TESTS) as a ctest executable <family>_<name>_test.
# LIBS are linked to the library and its tests, TEST_LIBS (test helpers) to the tests only.
# SHADERS are listed so IDEs show them and the path is known: the technique gets the compile
# definition RTLAB_TECHNIQUE_DIR pointing at its folder, and shaders are compiled at run time.
function(rtlab_add_technique name)
    cmake_parse_arguments(_t "" "FAMILY" "SOURCES;SHADERS;TESTS;LIBS;TEST_LIBS" ${ARGN})
    get_filename_component(_folder "${CMAKE_CURRENT_SOURCE_DIR}" NAME)
    get_filename_component(_parent_dir "${CMAKE_CURRENT_SOURCE_DIR}" DIRECTORY)
    get_filename_component(_parent "${_parent_dir}" NAME)
    if(NOT _t_FAMILY)
        message(FATAL_ERROR "rtlab_add_technique(${name}): FAMILY is required")
    endif()
    if(NOT _folder STREQUAL name OR NOT _parent STREQUAL _t_FAMILY)
        message(FATAL_ERROR "rtlab_add_technique(${name} FAMILY ${_t_FAMILY}) must be called from "
                            "techniques/${_t_FAMILY}/${name}/, not from ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
    if(NOT name MATCHES "^[a-z][a-z0-9_]*$")
        message(FATAL_ERROR "technique name '${name}' must be snake_case ([a-z][a-z0-9_]*)")
    endif()
    set(_target rtlab_technique_${_t_FAMILY}_${name})
    add_library(${_target} STATIC ${_t_SOURCES} ${_t_SHADERS})
    target_include_directories(${_target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
    target_link_libraries(${_target} PUBLIC rtlab_plugin PRIVATE rtlab_warnings ${_t_LIBS})
    target_compile_definitions(${_target} PRIVATE RTLAB_TECHNIQUE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
    set_property(GLOBAL APPEND PROPERTY RTLAB_TECHNIQUES "${_t_FAMILY}:${name}")
    set_property(GLOBAL APPEND PROPERTY RTLAB_TECHNIQUE_TARGETS ${_target})
    if(_t_TESTS)
        rtlab_add_test(${_t_FAMILY}_${name}_test SOURCES ${_t_TESTS}
            LIBS ${_target} rtlab_families ${_t_LIBS} ${_t_TEST_LIBS} LABELS "technique;${_t_FAMILY}")
        target_include_directories(${_t_FAMILY}_${name}_test PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
        target_compile_definitions(${_t_FAMILY}_${name}_test PRIVATE
            RTLAB_TECHNIQUE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
endfunction()
