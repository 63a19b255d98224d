#!/usr/bin/env bash
# The appearance kernels switched from the presets: the preset, colour toggled, semantics on with
# the colour-rule labels (cvo_make_labels), each on a TUM and a KITTI folder; frame-to-frame RPE,
# tracking counts and silent failures per run. With --check (CI, on the fixtures): every frame
# tracked, no silent failure, and each run within 1.5x of the preset in translation and rotation.
# Usage: bench/kernel_switches.sh BIN_DIR TUM_DIR KITTI_DIR [--check]
set -euo pipefail
bin=$1 tum=$2 kitti=$3 check=${4:-}
root="$(cd "$(dirname "$0")/.." && pwd)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/cvo_make_labels" --images "$tum/rgb" --out "$work/tum_labels"
"$bin/cvo_make_labels" --images "$kitti/image_0" --out "$work/kitti_labels"
failures=0
printf '| %-6s | %-34s | %7s | %7s | %-22s | %6s |\n' data run "RPE mm" "RPE deg" tracking silent
printf '|---|---|---|---|---|---|\n'
run() {  # data label options...
  local data=$1 label=$2
  shift 2
  local dir=$tum preset=tum_rgbd gt=$tum/groundtruth.txt
  if [ "$data" = kitti ]; then dir=$kitti preset=kitti_stereo gt=$kitti/poses.txt; fi
  "$bin/cvo_run_sequence" "--$data" "$dir" --preset "$preset" --backend cpu --quiet --gt "$gt" \
    "$@" >"$work/out.txt" 2>&1 || { echo "run failed: $data $label"; cat "$work/out.txt"; exit 1; }
  awk -v data="$data" -v label="$label" '
    /^RPE frame-to-frame/ && !seen++ { t = $5 * 1000; r = $7 }  # ours; the prior'"'"'s follows
    /^tracking:/ { tracked = $2; lost = $6; resets = $8 }
    /^silent failures:/ { silent = $3 }
    END { printf "| %-6s | %-34s | %7.2f | %7.3f | %5d tracked, %2d lost | %6d |\n",
                 data, label, t, r, tracked, lost, silent
          print t, r, lost + resets, silent > "/dev/stderr" }' "$work/out.txt" 2>"$work/figures.txt"
  read -r t r bad silent <"$work/figures.txt"
  if [ "$label" = preset ]; then base_t=$t base_r=$r; fi
  if [ -n "$check" ]; then
    awk -v t="$t" -v r="$r" -v bt="$base_t" -v br="$base_r" -v bad="$bad" -v s="$silent" \
      'BEGIN { exit !(bad == 0 && s == 0 && t <= 1.5 * bt && r <= 1.5 * br) }' || {
      echo "FAIL: $data $label: $t mm / $r deg (preset $base_t / $base_r), $bad lost or reset, $silent silent"
      failures=$((failures + 1))
    }
  fi
}
labels=(--segmentation "$work/tum_labels" --semantic-classes 6 --use-semantics true)
run tum preset
run tum "colour on" --use-color true
run tum "semantics on (colour labels)" "${labels[@]}"
run tum "colour and semantics on" --use-color true "${labels[@]}"
labels=(--segmentation "$work/kitti_labels" --semantic-classes 6 --use-semantics true)
run kitti preset
run kitti "colour off" --use-color false
run kitti "semantics on (colour labels)" "${labels[@]}"
run kitti "colour off, semantics on" --use-color false "${labels[@]}"
[ "$failures" = 0 ] || exit 1
