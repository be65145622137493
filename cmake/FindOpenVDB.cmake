# Finds OpenVDB (Debian 12: libopenvdb-dev 10.0.1) and defines the imported target
# OpenVDB::openvdb, OpenVDB_VERSION and OpenVDB_FOUND.
#
# Why not the package's own module (/usr/lib/x86_64-linux-gnu/cmake/OpenVDB/FindOpenVDB.cmake, used
# with list(APPEND CMAKE_MODULE_PATH ...)): it calls find_package(Boost REQUIRED COMPONENTS iostreams)
# unconditionally, and libopenvdb-dev does not depend on libboost-iostreams-dev, so it fails on a
# machine with only the packages of scripts/debian-packages.txt. That folder also holds its own
# FindTBB.cmake, which would shadow TBB's config for every later find_package(TBB). Boost iostreams
# is only needed to link code that reads .vdb files with delayed loading, which rtlab does not;
# libopenvdb.so itself brings the runtime library. The headers need TBB and Imath (half).
find_path(OpenVDB_INCLUDE_DIR NAMES openvdb/version.h)
find_library(OpenVDB_LIBRARY NAMES openvdb)

if(OpenVDB_INCLUDE_DIR AND EXISTS "${OpenVDB_INCLUDE_DIR}/openvdb/version.h")
    file(STRINGS "${OpenVDB_INCLUDE_DIR}/openvdb/version.h" _openvdb_version_lines
         REGEX "^#define OPENVDB_LIBRARY_(MAJOR|MINOR|PATCH)_VERSION_NUMBER ")
    foreach(_part MAJOR MINOR PATCH)
        string(REGEX REPLACE ".*OPENVDB_LIBRARY_${_part}_VERSION_NUMBER ([0-9]+).*" "\\1"
               _openvdb_${_part} "${_openvdb_version_lines}")
    endforeach()
    set(OpenVDB_VERSION "${_openvdb_MAJOR}.${_openvdb_MINOR}.${_openvdb_PATCH}")
endif()

find_package(TBB CONFIG QUIET)
# Imath (libimath-dev) by header and library: its CMake config also lists the Python bindings,
# which Debian ships in another package, and reports them missing on every configure.
find_path(OpenVDB_IMATH_INCLUDE_DIR NAMES Imath/half.h)
find_library(OpenVDB_IMATH_LIBRARY NAMES Imath-3_1 Imath)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenVDB
    REQUIRED_VARS OpenVDB_LIBRARY OpenVDB_INCLUDE_DIR OpenVDB_IMATH_INCLUDE_DIR
                  OpenVDB_IMATH_LIBRARY TBB_FOUND
    VERSION_VAR OpenVDB_VERSION)

if(OpenVDB_FOUND AND NOT TARGET OpenVDB::openvdb)
    add_library(OpenVDB::openvdb UNKNOWN IMPORTED)
    set_target_properties(OpenVDB::openvdb PROPERTIES
        IMPORTED_LOCATION "${OpenVDB_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenVDB_INCLUDE_DIR};${OpenVDB_IMATH_INCLUDE_DIR}"
        INTERFACE_LINK_LIBRARIES "TBB::tbb;${OpenVDB_IMATH_LIBRARY};Threads::Threads")
endif()
mark_as_advanced(OpenVDB_INCLUDE_DIR OpenVDB_LIBRARY OpenVDB_IMATH_INCLUDE_DIR OpenVDB_IMATH_LIBRARY)
