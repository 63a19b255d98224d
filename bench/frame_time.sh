#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# Time per frame of ours and the two fastest OpenCV peers, side by side in one run on the same
# TUM frames, as a markdown table (method | median ms | p95 ms | ratio to the fastest peer).
# Usage: bench/frame_time.sh [TUM_DIR]   (default: the bundled fr1_xyz excerpt)
# Builds like bench/peer_table.sh (bench/peer_build.sh: Release, build/peers). The ratio is each
# row's median over the fastest peer's median. All three take decoded images and give a pose:
#   ours: cvo_run_sequence's `total` (TUM preset): OdometryPipeline::process, i.e. the stale
#     check, the front end's cloud, the feature prior (KLT + PnP) and the registration with its
#     checks; decoding the PNGs is its `decode` stage, outside `total`.
#   OpenCV: cvo_peers' `frame`: grey conversion, depth to metres and Odometry::compute; reading
#     the PNGs is outside it. OpenCV gets the frame's grey and depth only (no point selection).
# Every frame but the first is timed (the first only seeds the next), on the same frames.
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
# shellcheck source=peer_build.sh
source "$CVO_ROOT/bench/peer_build.sh"
data=${1:-$CVO_ROOT/test/data/tum_fr1_xyz}
[ -f "$data/associations.txt" ] || [ -f "$data/rgb.txt" ] ||
  { echo "usage: $0 [TUM_DIR] (no TUM listing in '$data')" >&2; exit 2; }

peer_build
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# "label|median|p95" per method, from each tool's timing block (median and p95 columns).
rows=()
"$runner" --tum "$data" --preset "$CVO_ROOT/config/tum_rgbd.yaml" --set backend=cpu --quiet \
  --out "$work/ours.txt" \
  >"$work/ours.out" 2>"$work/ours.log" || { cat "$work/ours.log" >&2; exit 1; }
rows+=("ours (TUM preset, total)|$(awk '/^  total/ {print $2 "|" $3}' "$work/ours.out")")
for entry in "OpenCV RgbdOdometry|opencv_rgbd" "OpenCV ICPOdometry|opencv_icp"; do
  IFS='|' read -r label method <<<"$entry"
  "$peers" --tum "$data" --method "$method" --out "$work/$method.txt" >"$work/$method.out" \
    2>"$work/$method.log" || { cat "$work/$method.log" >&2; exit 1; }
  rows+=("$label|$(awk '/^  frame/ {print $2 "|" $3}' "$work/$method.out")")
done

frames=$(grep -vc '^#' "$work/ours.txt" || true)
echo "TUM $(basename "$data"): $frames frames, $(cvo_jobs) cores" \
  "(ours: its block pool of threads; OpenCV: its own)"
printf '%s\n' "${rows[@]}" | awk -F'|' '
  { label[NR] = $1; median[NR] = $2; p95[NR] = $3
    if (NR > 1 && (fastest == "" || $2 < fastest)) fastest = $2 }  # rows after ours are peers
  END {
    printf "| %-26s | %9s | %9s | %26s |\n", "method", "median ms", "p95 ms",
           "ratio to the fastest peer"
    printf "|----------------------------|-----------|-----------|----------------------------|\n"
    for (i = 1; i <= NR; ++i)
      printf "| %-26s | %9.2f | %9.2f | %24.2f x |\n", label[i], median[i], p95[i],
             median[i] / fastest
  }'
echo "The ratio compares the same frames, decoded images in and pose out as far as each tool"
echo "allows: ours' total (front end, feature prior, registration; no PNG decoding) against"
echo "cvo_peers' frame (grey and metric depth conversion, Odometry::compute; no PNG decoding)."
