#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# Time per frame idle and beside two CPU-bound processes (issue 21: "under load"), 2 threads
# against 1, in interleaved rounds so that each round's runs share the machine's minute. Each
# round: one idle run with 2 threads and one with 1, then two busy loops start and two runs of
# each follow. Prints each run's median / p95 ms (cvo_run_sequence's `total`, TUM preset) and
# the cores it got (`cores in use`: its CPU time over that wall time; loaded, about 0.9 where the
# scheduler left it a core of its own, about 0.6 where it shares one with a busy loop) and, at
# the end, the median of the runs' medians for each of the four cases.
# Usage: bench/load_time.sh [ROUNDS] [TUM_DIR]   (defaults: 5, the bundled fr1_xyz excerpt)
# Builds like bench/peer_table.sh (bench/peer_build.sh: Release, build/peers).
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
# shellcheck source=peer_build.sh
source "$CVO_ROOT/bench/peer_build.sh"
rounds=${1:-5}
data=${2:-$CVO_ROOT/test/data/tum_fr1_xyz}
peer_build

work=$(mktemp -d)
# One run with $1 threads: "median/p95@cores" of its total (the runner's log in $work on
# failure).
run() {
  "$runner" --tum "$data" --preset "$CVO_ROOT/config/tum_rgbd.yaml" \
    --set "backend=cpu,num_threads=$1" --quiet >"$work/out" 2>"$work/log" ||
    { cat "$work/log" >&2; return 1; }
  awk '/^  total/ {t = $2 "/" $3} /^cores in use/ {c = $4} END {print t "@" c}' "$work/out"
}
busy_loops=()
stop_loops() {
  [ ${#busy_loops[@]} -eq 0 ] || kill "${busy_loops[@]}" 2>/dev/null || true
  wait 2>/dev/null || true
  busy_loops=()
}
trap 'stop_loops; rm -rf "$work"' EXIT

declare -A medians
for round in $(seq 1 "$rounds"); do
  idle2=$(run 2) idle1=$(run 1)
  for _ in 1 2; do
    bash -c 'while :; do :; done' &
    busy_loops+=($!)
  done
  loaded2=$(run 2) loaded1=$(run 1)
  loaded2b=$(run 2) loaded1b=$(run 1)
  stop_loops
  echo "round $round (median/p95 ms@cores): idle 2 threads $idle2, 1 thread $idle1;" \
    "two busy loops: 2 threads $loaded2 $loaded2b, 1 thread $loaded1 $loaded1b"
  medians[idle2]+="${idle2%/*} " medians[idle1]+="${idle1%/*} "
  medians[loaded2]+="${loaded2%/*} ${loaded2b%/*} " medians[loaded1]+="${loaded1%/*} ${loaded1b%/*} "
done
median_of() { tr ' ' '\n' <<<"$1" | sed '/^$/d' | sort -g | awk '{v[NR] = $1}
  END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }
i2=$(median_of "${medians[idle2]}") i1=$(median_of "${medians[idle1]}")
l2=$(median_of "${medians[loaded2]}") l1=$(median_of "${medians[loaded1]}")
echo "medians of the runs' medians: idle $i2 (2 threads) / $i1 (1 thread);" \
  "loaded $l2 (2 threads) / $l1 (1 thread)"
awk -v i2="$i2" -v l2="$l2" -v l1="$l1" 'BEGIN {
  printf "loaded / idle with 2 threads: %.2fx; loaded 2 threads / 1 thread: %.2fx\n",
         l2 / i2, l2 / l1 }'
