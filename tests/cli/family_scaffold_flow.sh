#!/usr/bin/env bash
# The whole "add a family" flow as a user runs it, on a copy of the source tree:
#   rtlab new-family toy_family  ->  rebuild  ->  rtlab list shows the family and its first
#   technique  ->  the technique's unit test passes  ->  rtlab run of the family's experiment
#   writes rows and a report. Nothing central is edited: the family folder is found by CMake.
# Usage: family_scaffold_flow.sh <source dir> <rtlab executable> <work dir>
set -euo pipefail
src=$1
rtlab=$2
work=$3

rm -rf "$work"
mkdir -p "$work/tree"
for item in CMakeLists.txt cmake framework techniques tests notebooks_cpp experiments scenes; do
    cp -r "$src/$item" "$work/tree/"
done
rm -rf "$work/tree/framework/families/toy_family" "$work/tree/techniques/toy_family" \
       "$work/tree/techniques/_template/toy_family" "$work/tree/experiments/toy_family.yaml"
checksums() { (cd "$work/tree" && find . -type f ! -path "./framework/families/toy_family/*" \
    ! -path "./techniques/toy_family/*" ! -path "./techniques/_template/toy_family/*" \
    ! -path "./experiments/toy_family.yaml" -print0 | sort -z | xargs -0 md5sum); }
before=$(checksums)

"$rtlab" new-family toy_family --source-dir "$work/tree"

# Only new files: no file that existed before was changed or added elsewhere.
after=$(checksums)
[ "$after" = "$before" ] || { echo "new-family edited files outside the new folders:"; diff <(echo "$before") <(echo "$after"); exit 1; }
test -f "$work/tree/framework/families/toy_family/toy_family_family.cpp"

# Share the project's compiler cache (see scaffold_flow.sh).
export CCACHE_BASEDIR="$work/tree"
if [ -d "$src/.cache/ccache" ]; then
    export CCACHE_DIR="$src/.cache/ccache"
fi
cmake -S "$work/tree" -B "$work/tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DRTLAB_SANITIZE=${4:-OFF}" >"$work/configure.log"
cmake --build "$work/tree/build" --target rtlab toy_family_toy_family_example_test >"$work/build.log" 2>&1 \
    || { tail -n 40 "$work/build.log"; exit 1; }

listing=$("$work/tree/build/rtlab" list --family toy_family)
echo "$listing"
grep -q "toy_family" <<<"$listing"
grep -q "toy_family_example: describe toy_family_example in one line" <<<"$listing"
grep -qE "scale +float +1 +\[0, 1\]" <<<"$listing"
"$work/tree/build/techniques/toy_family/toy_family_example/toy_family_toy_family_example_test"

# A study of the new family: rows with its metric, and a report.
(cd "$work/tree" && build/rtlab run experiments/toy_family.yaml --output "$work/results")
# The family's stress cases come with the scaffold: its example technique passes them.
"$work/tree/build/rtlab" stress --family toy_family --cpu-only -o "$work/stress"
test -s "$work/results/results.csv"
head -n 1 "$work/results/results.csv" | tr ',' '\n' | grep -qx "toy_family.rmse"
grep -q '"status":"ok"' "$work/results/results.jsonl"
test -s "$work/results/report.html"
ls "$work/results/plots" | grep -q "time_vs_error"
rm -rf "$work"
echo "family scaffold flow: ok"
