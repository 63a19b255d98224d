#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# The accuracy table of README: ours and the peers on the same frames, one markdown table.
# Usage: bench/peer_table.sh tum [TUM_DIR] [--stride N]     (default: the bundled fr1_xyz excerpt)
#        bench/peer_table.sh kitti [KITTI_DIR] [--stride N] (default: the bundled KITTI 06 frames
#                                               0-7; README's table used the 51-frame excerpt)
#   --stride N  every method runs on every N-th frame of the whole sequence (frames 0, N, 2N..),
#               frame k against frame k-N with the guess each uses at stride 1 (ours: its
#               preset's; the peers: the previous motion); RPE frame-to-frame then measures the
#               N-frame step (cvo_evaluate pairs consecutive estimated poses). Default 1.
# Installs the peers (scripts/install_deps.sh peers), builds with -DCVO_BUILD_PEERS=ON in
# build/peers (bench/peer_build.sh), runs each method and evaluates with cvo_evaluate. Every
# trajectory is written stamped (TUM format), so a strided or gappy one meets the ground truth
# at its own frames (cvo_evaluate associates each estimated pose by its stamp).
# Rows: ours, "feature prior alone (KLT + PnP)" (the prior ours computes, chained on its own:
# cvo_run_sequence --prior-out of the first ours run; its ms/frame is the prior's own stage,
# without the front end that makes its grey and depth images), then the peers. ms/frame: median,
# decoded images in and pose out (bench/frame_time.sh says what each tool's number covers).
# After the table: "fastest peer: ...; ours ... = R x", ours being the first ours row (the preset).
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
# shellcheck source=peer_build.sh
source "$CVO_ROOT/bench/peer_build.sh"

usage() { echo "usage: $0 tum|kitti [DIR] [--stride N]" >&2; exit 2; }
kind=${1:-tum}
[ $# -gt 0 ] && shift
case "$kind" in tum | kitti) ;; *) usage ;; esac  # before the build, which takes minutes
dir="" stride=1
while [ $# -gt 0 ]; do
  case "$1" in
    --stride) [ $# -ge 2 ] || usage; stride=$2; shift 2 ;;
    -*) usage ;;
    *) [ -z "$dir" ] || usage; dir=$1; shift ;;
  esac
done
[[ "$stride" =~ ^[1-9][0-9]*$ ]] ||
  { echo "--stride: a positive integer, got '$stride'" >&2; exit 2; }

peer_build
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

case "$kind" in
  tum)
    data=${dir:-$CVO_ROOT/test/data/tum_fr1_xyz}
    seq=(--tum "$data")
    gt="$data/groundtruth.txt"
    eval_opts=()
    preset="$CVO_ROOT/config/tum_rgbd.yaml"
    # Every valid pixel: the grid's step is 1 px while (min + max) / 2 exceeds a quarter of them.
    full_cloud=(--point-selector grid --min-points 200000 --max-points 400000)
    methods=("ours (preset: geometric CVO + photometric rotation)|ours|"
      "ours colour|ours|--use-color true"
      "OpenCV RgbdOdometry|opencv_rgbd|" "OpenCV ICPOdometry|opencv_icp|"
      "OpenCV RgbdICPOdometry|opencv_rgbdicp|"
      "PCL GICP (full cloud, 1 cm voxels)|pcl_gicp|${full_cloud[*]}"
      "PCL NDT (full cloud, 1 cm voxels)|pcl_ndt|${full_cloud[*]}"
      "Open3D colored ICP|open3d_colored_icp|" "Open3D RGB-D odometry (hybrid)|open3d_rgbd_hybrid|")
    ;;
  kitti)
    data=${dir:-$CVO_ROOT/test/data/kitti_06_stereo}
    seq=(--kitti "$data")
    gt="$data/poses.txt"
    # The estimates are stamped (TUM format): only the KITTI ground truth needs times.txt.
    eval_opts=(--drift-lengths "10,20,30,40,50" --gt-times "$data/times.txt")
    preset="$CVO_ROOT/config/kitti_stereo.yaml"
    methods=("ours (preset: colour-intensity CVO)|ours|"
      "ours geometric|ours|--use-color false"
      "PCL GICP (our stereo clouds)|pcl_gicp|--preset $preset"
      "PCL NDT (our stereo clouds)|pcl_ndt|--preset $preset")
    ;;
  *) usage ;;
esac
prior_row="feature prior alone (KLT + PnP)|prior|"
# The prior row goes right after the first ours row, whose run writes it.
methods=("${methods[0]}" "$prior_row" "${methods[@]:1}")

echo "$kind $(basename "$data"), --stride $stride: frames 0, $stride, $((2 * stride)), ..."
printf '| %-36s | %9s | %9s | %9s | %9s | %10s | %8s | %8s |\n' method "RPE mm" "RPE deg" \
  "RPE m/s" "RPE deg/s" "1s RPE mm" "ATE mm" "ms/frame"
printf '|%s|%s|\n' "--------------------------------------" \
  "-----------|-----------|-----------|-----------|------------|----------|----------"
notes=()
ours_label="" ours_ms="" fastest_label="" fastest_ms=""
for entry in "${methods[@]}"; do
  IFS='|' read -r label method options <<<"$entry"
  est="$work/$method.txt" log="$work/$method.log"
  rc=0
  # shellcheck disable=SC2086  # $options holds several words on purpose
  case "$method" in
    ours)
      # Only the first ours run writes the prior's trajectory (the prior ignores use_color).
      prior_opts=()
      [ -e "$work/prior.txt" ] || prior_opts=(--prior-out "$work/prior.txt")
      # The CPU backend: a table of this machine's cores, even where a GPU is usable.
      "$runner" "${seq[@]}" --preset "$preset" --set backend=cpu $options --stride "$stride" \
        --quiet --format tum --out "$est" "${prior_opts[@]}" >"$work/ours.out" 2>"$log" || rc=$?
      prior_log=$log
      timing=$(awk '/^  total/ {print $2}' "$work/ours.out")
      # The feature prior's own stage time of that run, for the prior's row.
      [ ${#prior_opts[@]} -eq 0 ] ||
        prior_ms=$(awk '/^  feature prior/ {print $3}' "$work/ours.out")
      ;;
    prior) est="$work/prior.txt" timing=${prior_ms:-} log=${prior_log:-$log} ;;
    open3d_*)
      # One thread: Open3D's colored ICP is not repeatable on several (37.1 and 13.9 mm on two
      # runs of the same frames; 7.4 mm on one thread, every time).
      OMP_NUM_THREADS=1 /usr/bin/python3 "$open3d_peers" "$data" "$method" "$est" --stride "$stride" \
        >"$work/peer.out" 2>"$log" || rc=$?
      timing=$(awk '/^  frame/ {print $2}' "$work/peer.out")
      ;;
    *)
      "$peers" "${seq[@]}" --method "$method" $options --stride "$stride" --format tum \
        --out "$est" >"$work/peer.out" 2>"$log" || rc=$?
      timing=$(awk '/^  frame/ {print $2}' "$work/peer.out")
      ;;
  esac
  if [ "$rc" -ne 0 ] || [ ! -s "$est" ]; then
    printf '| %-36s | %s |\n' "$label" "failed (exit $rc): $(tail -1 "$log" 2>/dev/null)"
    continue
  fi
  # Frames where a peer kept its guess: a failure the table's numbers would hide.
  kept=0
  [ ! -e "$log" ] || kept=$(grep -c 'keeping the guess' "$log" || true)
  [ "$kept" -eq 0 ] ||
    notes+=("$label: failed on $kept frames and kept the previous motion (its own report)")
  if ! "$evaluate" --gt "$gt" --est "$est" "${eval_opts[@]}" >"$work/report.txt" \
      2>"$work/evaluate.log"; then
    printf '| %-36s | %s |\n' "$label" "not evaluated: $(tail -1 "$work/evaluate.log")"
    continue
  fi
  # Every pose must meet the ground truth, else RPE's pairs would span more than one step.
  read -r associated estimated < <(awk '/^poses:/ {print $2, $4}' "$work/report.txt") || true
  [ "$associated" = "$estimated" ] ||
    notes+=("$label: only $associated of $estimated poses associated with ground truth")
  awk -v label="$label" -v ms="${timing:-nan}" '
    /^RPE frame-to-frame/ { t = $5 * 1000; r = $7; tr = $9; rr = $11 }
    /^RPE delta/ { d = ($5 == "n/a") ? -1 : $7 * 1000 }
    /^ATE rmse/ { a = $3 * 1000 }
    /^drift/ { drift = $0 }
    END { printf "| %-36s | %9.2f | %9.3f | %9.4f | %9.3f | %10.2f | %8.2f | %8.1f |\n",
                 label, t, r, tr, rr, d, a, ms
          if (drift != "" && drift !~ /n\/a/) print "  " label ": " drift > "/dev/stderr" }' \
    "$work/report.txt"
  case "$method" in
    ours) [ -n "$ours_label" ] || { ours_label=$label ours_ms=$timing; } ;;
    prior) ;;
    *)
      if [ -n "$timing" ] && { [ -z "$fastest_ms" ] ||
          awk -v a="$timing" -v b="$fastest_ms" 'BEGIN { exit !(a < b) }'; }; then
        fastest_label=$label fastest_ms=$timing
      fi
      ;;
  esac
done
for note in "${notes[@]}"; do echo "  note: $note"; done
if [ -n "$fastest_ms" ] && [ -n "$ours_ms" ]; then
  awk -v peer="$fastest_label" -v p="$fastest_ms" -v ours="$ours_label" -v o="$ours_ms" 'BEGIN {
    printf "fastest peer: %s %.1f ms/frame; ours %.1f ms/frame = %.2f x (ours = %s)\n",
           peer, p, o, o / p, ours }'
fi
