#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# Near scenes from a TUM sequence: the same frames with every depth times S, as a camera S times
# as far from the same surfaces would see them (the front end picks the same pixels, so the
# points crowd together in 3D as on a desk or a tabletop). Depth is read with depth_scale
# 5000 / S and the ground truth's positions are scaled by S, so errors come out in the scaled
# scene's own units. For each S and each point_spacing P: mm / deg a frame, ATE mm,
# registration and total median ms (cvo_run_sequence, TUM preset, CPU backend), frames tracked.
# Usage: bench/near_scene.sh [TUM_DIR] [SCALES] [SPACINGS]
#   defaults: the bundled fr1_xyz excerpt, "1 0.5 0.35", "0 0.25"
# Builds like bench/frame_time.sh (bench/peer_build.sh: Release, build/peers).
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
# shellcheck source=peer_build.sh
source "$CVO_ROOT/bench/peer_build.sh"
data=${1:-$CVO_ROOT/test/data/tum_fr1_xyz}
scales=${2:-1 0.5 0.35}
spacings=${3:-0 0.25}
[ -f "$data/groundtruth.txt" ] ||
  { echo "usage: $0 [TUM_DIR] [SCALES] [SPACINGS] (no groundtruth.txt in '$data')" >&2; exit 2; }

peer_build
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "TUM $(basename "$data"), depth x S (depth_scale 5000 / S), $(cvo_jobs) cores"
printf '| %5s | %13s | %8s | %8s | %7s | %14s | %8s | %7s |\n' S point_spacing \
  "mm/frame" "deg" "ATE mm" "registration ms" "total ms" tracked
echo "|-------|---------------|----------|----------|---------|-----------------|----------|---------|"
for s in $scales; do
  awk -v s="$s" '/^#/ { print; next }
    { printf "%s %.9f %.9f %.9f %s %s %s %s\n", $1, $2 * s, $3 * s, $4 * s, $5, $6, $7, $8 }' \
    "$data/groundtruth.txt" >"$work/groundtruth.txt"
  depth_scale=$(awk -v s="$s" 'BEGIN { printf "%.6f", 5000 / s }')
  for p in $spacings; do
    "$runner" --tum "$data" --gt "$work/groundtruth.txt" --preset "$CVO_ROOT/config/tum_rgbd.yaml" \
      --set "backend=cpu,depth_scale=$depth_scale,point_spacing=$p" --quiet \
      >"$work/out" 2>"$work/log" || { cat "$work/log" >&2; exit 1; }
    awk -v s="$s" -v p="$p" '
      # The first RPE and ATE lines are ours (the feature prior alone follows).
      /^RPE frame-to-frame/ && !rpe { rpe = 1; mm = 1000 * $5; sub(/,/, "", $7); deg = $7 }
      /^ATE rmse/ && !seen_ate { seen_ate = 1; ate = 1000 * $3 }
      /^  registration/ { reg = $2 }
      /^  total/ { total = $2 }
      /^tracking:/ { tracked = $2 }
      END { printf "| %5s | %13s | %8.3f | %8.4f | %7.2f | %15.2f | %8.2f | %7s |\n",
                   s, p, mm, deg, ate, reg, total, tracked }' "$work/out"
  done
done
echo "Errors in the scaled scene's units (mm / deg a frame, frame to frame; ATE after alignment)."
