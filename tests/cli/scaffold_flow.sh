#!/usr/bin/env bash
# The whole "add a technique" flow as a user runs it, on a copy of the source tree:
#   rtlab new-technique occlusion flow_check_ao  ->  rebuild  ->  rtlab list shows it with its
#   parameters  ->  its unit test passes.
# Usage: scaffold_flow.sh <source dir> <rtlab executable> <work dir>
set -euo pipefail
src=$1
rtlab=$2
work=$3

rm -rf "$work"
mkdir -p "$work/tree"
for item in CMakeLists.txt cmake framework techniques tests notebooks_cpp experiments scenes; do
    cp -r "$src/$item" "$work/tree/"
done
rm -rf "$work/tree/techniques/occlusion/flow_check_ao"

"$rtlab" new-technique occlusion flow_check_ao --source-dir "$work/tree"

# Share the project's compiler cache: the copy builds in tree/build as the project builds in
# build/, so with the base directory set the relative paths match and its compilations hit the
# entries of the main build: this costs seconds, not a full build.
export CCACHE_BASEDIR="$work/tree"
if [ -d "$src/.cache/ccache" ]; then
    export CCACHE_DIR="$src/.cache/ccache"
fi
cmake -S "$work/tree" -B "$work/tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DRTLAB_SANITIZE=${4:-OFF}" >"$work/configure.log"
cmake --build "$work/tree/build" --target rtlab occlusion_flow_check_ao_test >"$work/build.log" 2>&1 \
    || { tail -n 40 "$work/build.log"; exit 1; }

listing=$("$work/tree/build/rtlab" list --family occlusion)
echo "$listing"
grep -q "flow_check_ao: describe flow_check_ao in one line" <<<"$listing"
grep -qE "radius +float +1 +\[0, inf\) +world units" <<<"$listing"
"$work/tree/build/techniques/occlusion/flow_check_ao/occlusion_flow_check_ao_test"
# The new technique is stressed with no code of its own: the template answers "no occlusion", so
# it passes the range cases and fails the crease's closed form (exit code 1, not 2 or 3).
set +e
stress=$("$work/tree/build/rtlab" stress --technique flow_check_ao --cpu-only -o "$work/stress")
code=$?
set -e
echo "$stress" | tail -n 4
[ "$code" -eq 1 ] || { echo "rtlab stress exit code $code, expected 1"; exit 1; }
grep -qE "FAIL +occlusion/flow_check_ao on crease_closed_form" <<<"$stress"
grep -qE "ok +occlusion/flow_check_ao on floor_and_wall_64x48" <<<"$stress"
[ -s "$work/stress/results.csv" ] && [ -s "$work/stress/heatmap_occlusion.png" ] && [ -s "$work/stress/stress.html" ]
rm -rf "$work"
echo "scaffold flow: ok"
