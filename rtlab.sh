#!/usr/bin/env bash
# rtlab's entry points on a fresh Debian 12 machine:
#
#   ./rtlab.sh run        set up, build, and run the default experiment (experiments/smoke.yaml)
#   ./rtlab.sh test       set up, build, and run the whole test suite with ctest
#   ./rtlab.sh sanitize   the same suite built in build-sanitize/ with AddressSanitizer and
#                         UndefinedBehaviorSanitizer, where any report fails its test
#
# Set-up installs the missing Debian packages listed in scripts/debian-packages.txt (as root, or
# through sudo), configures with CMake + Ninja (+ ccache) into build/, and builds. The commands
# are safe to run again: packages already present are not reinstalled, builds are incremental,
# and `rtlab run` resumes a study, skipping runs already in its results table.
set -euo pipefail
cd "$(dirname "$0")"

usage() {
    sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
}

action=${1:-}
case "$action" in
    run|test|sanitize) shift ;;
    -h|--help|help) usage; exit 0 ;;
    *) usage >&2; exit 2 ;;
esac

if [ "$action" = sanitize ]; then
    RTLAB_BUILD_DIR=build-sanitize RTLAB_CMAKE_ARGS="-DRTLAB_SANITIZE=ON" scripts/setup.sh
else
    scripts/setup.sh
fi

case "$action" in
    run)
        build/rtlab run experiments/smoke.yaml "$@"
        ;;
    test)
        # Tests run two at a time: each is small, and ctest's own timeout guards against hangs.
        ctest --test-dir build --output-on-failure --timeout 600 -j 2 "$@"
        ;;
    sanitize)
        # UBSan aborts on its first report (-fno-sanitize-recover, CMakeLists.txt), ASan always
        # does; leak checking is off: the Vulkan driver, VTK and Embree keep process-lifetime
        # allocations that are not leaks. Tests run about twice as slowly, hence the timeout.
        ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:strict_string_checks=1:detect_stack_use_after_return=1} \
        UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
            ctest --test-dir build-sanitize --output-on-failure --timeout 1800 -j 2 "$@"
        ;;
esac
