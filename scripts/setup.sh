#!/usr/bin/env bash
# Installs missing Debian packages, configures (CMake + Ninja + ccache) and builds rtlab in build/
# (or $RTLAB_BUILD_DIR).
# Idempotent: a second run installs nothing and rebuilds only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=$(grep -vE '^\s*(#|$)' scripts/debian-packages.txt)
missing=()
for p in $packages; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "rtlab setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "rtlab setup: run as root or install sudo" >&2; exit 1; }
        sudo="sudo"
    fi
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# ccache keeps rebuilds on 2 cores short; keep its cache in the project's own folder when the
# user has not chosen one, so that a fresh machine needs nothing outside the checkout.
export CCACHE_DIR=${CCACHE_DIR:-$PWD/.cache/ccache}
# Paths under the checkout are hashed relative to it, so copies of the tree (the scaffold test)
# share the cache.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
# RTLAB_BUILD_DIR and RTLAB_CMAKE_ARGS choose another build (./rtlab.sh sanitize: build-sanitize/
# with -DRTLAB_SANITIZE=ON).
build_dir=${RTLAB_BUILD_DIR:-build}
if [ ! -f "$build_dir/build.ninja" ]; then
    # shellcheck disable=SC2086
    cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release ${RTLAB_CMAKE_ARGS:-}
fi
cmake --build "$build_dir"
