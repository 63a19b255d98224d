#!/usr/bin/env bash
# Usage: run_fuzzer.sh FUZZER REGRESSIONS_DIR WORK_DIR SECONDS [SEED_DIR...]
# Replays every kept regression input, then fuzzes for SECONDS from the seeds (new inputs go to
# WORK_DIR/corpus, a crash to WORK_DIR/crash-*). Exits non-zero on any finding.
set -euo pipefail
fuzzer=$1 regressions=$2 work=$3 seconds=$4
shift 4
mkdir -p "$work/corpus"
if compgen -G "$regressions/*" >/dev/null; then
  echo "replaying $(ls "$regressions" | wc -l) regression inputs from $regressions"
  "$fuzzer" -runs=1 "$regressions"/*
fi
seeds=()
for dir in "$@"; do [ -d "$dir" ] && seeds+=("$dir"); done
"$fuzzer" -max_total_time="$seconds" -seed=1 -max_len=16384 -rss_limit_mb=4096 \
  -timeout=20 -print_final_stats=1 -artifact_prefix="$work/" "$work/corpus" "${seeds[@]}"
