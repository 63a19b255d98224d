#!/usr/bin/env bash
# Usage: run_fuzzer.sh FUZZER REGRESSIONS_DIR CORPUS_DIR WORK_DIR RUNS SEED [SEED_DIR...]
# CI's fuzz stage, the same for a given commit on any machine and at any speed: replays every
# kept regression input, then runs the fuzzer a fixed number of times (-runs=RUNS; libFuzzer
# counts the replay of the committed corpus CORPUS_DIR and the seeds in it) from a fixed random
# seed (-seed=SEED), in one process, OpenMP on one thread (the front-end target also puts OpenCV
# on one). Nothing depends on time or addresses:
# - no time limit (-max_total_time), no periodic corpus reload (-reload=0) or allocator purge
#   (-purge_allocator_interval=-1), and a per-input timeout (-timeout=300 s) far above any
#   input's time (the slowest here takes well under 1 s);
# - -use_cmp=0: libFuzzer's compare tracing feeds operands of the target's comparisons, pointers
#   included, into its mutations, so with address randomisation two runs of the same commit
#   mutated differently (fuzz_frontend from its seeds: cov 610 or 674 after 20000 runs; with
#   -use_cmp=0, 764 in four runs). Compare-guided fuzzing stays on in test/fuzz/fuzz_longer.sh.
#   (The stack depth feature, which varied the same way, is left out of the build:
#   CMakeLists.txt.)
# New inputs go to WORK_DIR/new (emptied first: an earlier run changes nothing, and the committed
# corpus is only read), a crash to WORK_DIR/crash-*. Exits non-zero on any finding.
set -euo pipefail
fuzzer=$1 regressions=$2 corpus=$3 work=$4 runs=$5 seed=$6
shift 6
export OMP_NUM_THREADS=1
rm -rf "$work/new"
mkdir -p "$work/new"
if compgen -G "$regressions/*" >/dev/null; then
  echo "replaying $(ls "$regressions" | wc -l) regression inputs from $regressions"
  "$fuzzer" -runs=1 "$regressions"/*
fi
inputs=()
for dir in "$corpus" "$@"; do [ -d "$dir" ] && inputs+=("$dir"); done
echo "fuzzing: -runs=$runs -seed=$seed from ${inputs[*]}"
"$fuzzer" -runs="$runs" -seed="$seed" -max_len=16384 -rss_limit_mb=4096 -timeout=300 \
  -reload=0 -purge_allocator_interval=-1 -use_cmp=0 -print_final_stats=1 \
  -artifact_prefix="$work/" "$work/new" "${inputs[@]}"
