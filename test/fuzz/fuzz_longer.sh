#!/usr/bin/env bash
# Longer, time-bounded fuzzing on this machine, to find more and to grow the committed corpus
# (not CI: how far a time-bounded run gets depends on the machine; CI runs test/fuzz/run_fuzzer.sh,
# a fixed number of runs from a fixed seed).
# Usage: test/fuzz/fuzz_longer.sh [--seconds N] [--max-len BYTES] [--merge] [TARGET...]
#   TARGET: fuzz_frontend, fuzz_params, fuzz_stamp_pairer (default: all), each for N seconds
#   (default 600) from the committed corpus test/fuzz/corpus/TARGET, the seeds and what earlier
#   runs found (kept in BUILD/fuzz/TARGET/grown), with a random seed and libFuzzer's
#   compare-guided mutations; a crash leaves BUILD/fuzz/TARGET/crash-* (fix it, then keep the
#   input in test/fuzz/regressions/TARGET/). BUILD: $CVO_SANITIZE_BUILD or build-sanitize, as
#   configured by scripts/test_sanitizers.sh (run that first).
#   --max-len: the longest input (default 16384, as in CI); longer ones are cut when loaded.
#   --merge: then rewrite test/fuzz/corpus/TARGET as the smallest set of the old corpus and the
#   grown inputs (those of at most --max-len bytes) that keeps their coverage beyond the seeds'
#   (libFuzzer -merge=1, which prefers small inputs); review its size (README: keep the corpus a
#   few hundred KB; fuzz_frontend's was made with --max-len 2048) and commit it.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${CVO_SANITIZE_BUILD:-$root/build-sanitize}"
seconds=600 max_len=16384 merge=0 targets=()
while [ $# -gt 0 ]; do
  case $1 in
    --seconds) seconds=$2; shift 2 ;;
    --max-len) max_len=$2; shift 2 ;;
    --merge) merge=1; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_frontend fuzz_params fuzz_stamp_pairer)
[ -f "$build/CMakeCache.txt" ] || { echo "no sanitizer build in $build: run scripts/test_sanitizers.sh first" >&2; exit 1; }
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}" >/dev/null
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
for target in "${targets[@]}"; do
  fuzzer="$build/test/fuzz/$target" work="$build/fuzz/$target"
  corpus="$root/test/fuzz/corpus/$target" seeds="$root/test/fuzz/seeds/$target"
  mkdir -p "$work/grown" "$corpus"
  inputs=("$corpus")
  [ -d "$seeds" ] && inputs+=("$seeds")
  echo "== $target: $seconds s from ${inputs[*]} (found so far: $work/grown)"
  "$fuzzer" -max_total_time="$seconds" -max_len="$max_len" -rss_limit_mb=4096 -timeout=20 \
    -print_final_stats=1 -artifact_prefix="$work/" "$work/grown" "${inputs[@]}"
  if [ "$merge" = 1 ]; then
    merged="$(mktemp -d)" candidates="$(mktemp -d)"
    find "$corpus" "$work/grown" -type f -size -$((max_len + 1))c -exec cp {} "$candidates"/ \;
    # The seeds first, so that only what adds to their coverage is kept; then drop them again.
    [ -d "$seeds" ] && cp "$seeds"/* "$merged"/
    "$fuzzer" -merge=1 -max_len=16384 -rss_limit_mb=4096 -timeout=20 "$merged" "$candidates"
    [ -d "$seeds" ] && (cd "$seeds" && for f in *; do rm -f "$merged/$f"; done)
    rm -f "$corpus"/*
    cp "$merged"/* "$corpus"/ 2>/dev/null || true
    rm -rf "$merged" "$candidates"
    echo "== $target: corpus now $(ls "$corpus" | wc -l) inputs, $(cat "$corpus"/* | wc -c) bytes"
  fi
done
