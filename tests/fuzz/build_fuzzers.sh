#!/usr/bin/env bash
# Builds the fuzz targets with clang in a build folder of their own (CMake option RTLAB_FUZZ).
#   build_fuzzers.sh <source dir> <build dir>
set -euo pipefail
src=$1
dir=$2
command -v clang++ >/dev/null || { echo "build_fuzzers: clang++ is missing (Debian packages clang, libclang-rt-14-dev)" >&2; exit 1; }
export CCACHE_DIR=${CCACHE_DIR:-$src/.cache/ccache}
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$src}
if [ ! -f "$dir/build.ninja" ]; then
    cmake -S "$src" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRTLAB_FUZZ=ON \
        -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ >"$dir.configure.log" 2>&1 \
        || { tail -n 40 "$dir.configure.log"; exit 1; }
fi
cmake --build "$dir" >"$dir.build.log" 2>&1 || { grep -E 'error|FAILED' -A5 "$dir.build.log" | head -n 60; exit 1; }
ls "$dir"/tests/fuzz/fuzz_*
