#!/usr/bin/env bash
# Kill `rtlab run` halfway through a sweep, run it again, and check that the table is completed
# without recomputing the runs that had finished: the rows written before the kill are kept byte
# for byte, and the second invocation reports them as already done.
# Usage: resume_test.sh <rtlab executable> <work dir>
set -euo pipefail
rtlab=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
cat >"$work/study.yaml" <<'YAML'
name: resume_study
base:
  scene: torus
  grid: 128
  timing: {warmup: 1, repeats: 9}
  techniques: {isosurface: {technique: marching_cubes}}
sweep:
  isosurface.grain: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]
YAML
out="$work/out"
"$rtlab" run "$work/study.yaml" --output "$out" --no-report >"$work/first.log" 2>&1 &
pid=$!
# Wait until some but not all runs are in the table, then kill the process without warning.
for _ in $(seq 1 600); do
    rows=$( [ -f "$out/results.jsonl" ] && wc -l <"$out/results.jsonl" || echo 0)
    [ "$rows" -ge 3 ] && break
    sleep 0.1
done
kill -9 "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
before=$(wc -l <"$out/results.jsonl")
echo "killed after $before complete row(s)"
[ "$before" -ge 1 ] && [ "$before" -lt 12 ] || { echo "the kill did not land mid-sweep ($before rows)"; exit 1; }
cp "$out/results.jsonl" "$work/before.jsonl"

"$rtlab" run "$work/study.yaml" --output "$out" --no-report | tee "$work/second.log"
grep -q "resume_study: 12 run(s): $((12 - before)) computed, $before already done, 0 failed" "$work/second.log"
[ "$(wc -l <"$out/results.jsonl")" -eq 12 ]
# The rows from before the kill are unchanged, in place.
head -n "$before" "$out/results.jsonl" | cmp - "$work/before.jsonl"
# Every grain value is in the table exactly once.
[ "$(grep -o '"param.grain":"[0-9]*"' "$out/results.jsonl" | sort -u | wc -l)" -eq 12 ]
rm -rf "$work"
echo "resume after kill: ok"
