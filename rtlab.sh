#!/usr/bin/env bash
# rtlab's two entry points on a fresh Debian 12 machine:
#
#   ./rtlab.sh run    set up, build, and run the default experiment (experiments/smoke.yaml)
#   ./rtlab.sh test   set up, build, and run the whole test suite with ctest
#
# Set-up installs the missing Debian packages listed in scripts/debian-packages.txt (as root, or
# through sudo), configures with CMake + Ninja (+ ccache) into build/, and builds. Both commands
# are safe to run again: packages already present are not reinstalled, builds are incremental,
# and `rtlab run` resumes a study, skipping runs already in its results table.
set -euo pipefail
cd "$(dirname "$0")"

usage() {
    sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
}

action=${1:-}
case "$action" in
    run|test) shift ;;
    -h|--help|help) usage; exit 0 ;;
    *) usage >&2; exit 2 ;;
esac

scripts/setup.sh

case "$action" in
    run)
        build/rtlab run experiments/smoke.yaml "$@"
        ;;
    test)
        # Tests run two at a time: each is small, and ctest's own timeout guards against hangs.
        ctest --test-dir build --output-on-failure --timeout 600 -j 2 "$@"
        ;;
esac
