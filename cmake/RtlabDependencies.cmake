# Finds every third-party dependency. A missing one stops configuration with the Debian package
# that provides it, so `apt-get install <package>` is always the fix.

# rtlab_require(<find_package args...> DEBIAN <package>)
macro(rtlab_require name)
    cmake_parse_arguments(_rq "" "DEBIAN" "" ${ARGN})
    find_package(${name} ${_rq_UNPARSED_ARGUMENTS} QUIET)
    if(NOT ${name}_FOUND)
        message(FATAL_ERROR
            "rtlab: dependency '${name}' was not found.\n"
            "  Install the Debian package: apt-get install ${_rq_DEBIAN}\n"
            "  (./rtlab.sh installs every package listed in scripts/debian-packages.txt)")
    endif()
endmacro()

# rtlab_require_header(<var> <header> DEBIAN <package>) for header-only libraries without CMake files.
function(rtlab_require_header var header)
    cmake_parse_arguments(_rq "" "DEBIAN" "" ${ARGN})
    find_path(${var} NAMES ${header})
    if(NOT ${var})
        message(FATAL_ERROR
            "rtlab: header '${header}' was not found.\n"
            "  Install the Debian package: apt-get install ${_rq_DEBIAN}")
    endif()
endfunction()

# rtlab_require_library(<var> <libname> DEBIAN <package>)
function(rtlab_require_library var lib)
    cmake_parse_arguments(_rq "" "DEBIAN" "" ${ARGN})
    find_library(${var} NAMES ${lib})
    if(NOT ${var})
        message(FATAL_ERROR
            "rtlab: library '${lib}' was not found.\n"
            "  Install the Debian package: apt-get install ${_rq_DEBIAN}")
    endif()
endfunction()

find_package(PkgConfig QUIET)
rtlab_require(Threads DEBIAN libc6-dev)
rtlab_require(Vulkan DEBIAN libvulkan-dev)
rtlab_require(glm DEBIAN libglm-dev)
rtlab_require(TBB DEBIAN libtbb-dev)
rtlab_require(yaml-cpp DEBIAN libyaml-cpp-dev)
rtlab_require(CLI11 DEBIAN libcli11-dev)
rtlab_require(fmt DEBIAN libfmt-dev)
rtlab_require(GTest DEBIAN "libgtest-dev libgmock-dev")
rtlab_require(benchmark DEBIAN libbenchmark-dev)

rtlab_require(glslang CONFIG DEBIAN glslang-dev)
rtlab_require(SPIRV-Tools CONFIG DEBIAN spirv-tools)
rtlab_require(SPIRV-Tools-opt CONFIG DEBIAN spirv-tools)
add_library(rtlab_glslang INTERFACE)
target_link_libraries(rtlab_glslang INTERFACE
    glslang::glslang glslang::SPIRV glslang::glslang-default-resource-limits)

# Used from issue [2] on: ground truth, images, meshes, plots, baselines.
rtlab_require(embree 3 CONFIG DEBIAN libembree-dev)
rtlab_require(OpenImageIO CONFIG DEBIAN libopenimageio-dev)
# Debian 12's OpenImageIO package lists /usr/include/opencv4 among the include directories of
# OpenImageIO::OpenImageIO without depending on libopencv-dev; keep only the ones that exist.
foreach(_property INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
    get_target_property(_dirs OpenImageIO::OpenImageIO ${_property})
    if(_dirs)
        set(_existing "")
        foreach(_dir IN LISTS _dirs)
            if(EXISTS "${_dir}")
                list(APPEND _existing "${_dir}")
            endif()
        endforeach()
        set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${_property} "${_existing}")
    endif()
endforeach()

rtlab_require(TinyGLTF CONFIG DEBIAN libtinygltf-dev)
rtlab_require(VTK 9.1 CONFIG COMPONENTS ChartsCore CommonColor CommonCore CommonDataModel
    IOExportPDF IOImage RenderingContext2D RenderingContextOpenGL2 RenderingCore RenderingFreeType
    RenderingOpenGL2 CommonExecutionModel FiltersCore IOXML IOPLY DEBIAN libvtk9-dev)
# cmake/FindOpenVDB.cmake (the package's own module needs Boost iostreams' dev files; see there).
rtlab_require(OpenVDB 10 DEBIAN libopenvdb-dev)
