#!/usr/bin/env bash
# Runs one fuzz target for a fixed number of inputs, from a fresh corpus seeded with the given
# folders; fails on any crash, hang (10 s for one input), sanitizer report or out-of-memory.
#   run_fuzzer.sh <fuzzer> <corpus dir> <runs> <seed dir>...
set -euo pipefail
fuzzer=$1
corpus=$2
runs=$3
shift 3
rm -rf "$corpus" "$corpus.crashes"
mkdir -p "$corpus" "$corpus.crashes"
# -seed fixes the mutations: the same inputs on every machine. Crash inputs land in
# <corpus>.crashes; reproduce one with `<fuzzer> <file>`.
# A single allocation may exceed the memory limit (a decoder reserving address space for a size
# it then refuses): only memory in use counts (-rss_limit_mb), and a failed allocation returns
# null to the allocator's caller, which must handle it (allocator_may_return_null).
ASAN_OPTIONS=${ASAN_OPTIONS:-allocator_may_return_null=1} \
"$fuzzer" -runs="$runs" -seed=1 -max_len=16384 -timeout=10 -rss_limit_mb=4096 -malloc_limit_mb=1000000 \
    -print_final_stats=1 -artifact_prefix="$corpus.crashes/" "$corpus" "$@" 2>&1 | tail -n 40
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ] || [ -n "$(ls -A "$corpus.crashes")" ]; then
    echo "run_fuzzer: $(basename "$fuzzer") failed (exit $status); inputs in $corpus.crashes:" >&2
    ls -l "$corpus.crashes" >&2
    exit 1
fi
