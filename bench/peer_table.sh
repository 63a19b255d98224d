#!/usr/bin/env bash
# The accuracy table of README: ours and the peers on the same frames, one markdown table.
# Usage: bench/peer_table.sh tum [TUM_DIR]     (default: the bundled fr1_xyz excerpt)
#        bench/peer_table.sh kitti [KITTI_DIR] (default: the bundled KITTI 06 frames 0-7;
#                                               README's table used the 51-frame excerpt)
# Installs the peers (scripts/install_deps.sh peers), builds with -DCVO_BUILD_PEERS=ON in
# build/peers, runs each method frame to frame and evaluates with cvo_evaluate.
set -euo pipefail
source "$(dirname "$0")/../scripts/env.sh"
kind=${1:-tum}
"$CVO_ROOT/scripts/install_deps.sh" peers
build="$CVO_ROOT/build/peers"
mkdir -p "$build"
{ cmake -S "$CVO_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCVO_WITH_ROS=OFF \
    -DCVO_BUILD_TESTS=OFF -DCVO_BUILD_PEERS=ON &&
  cmake --build "$build" -j"$(cvo_jobs)" --target cvo_peers cvo_run_sequence cvo_evaluate; } \
  >"$build/build.log" 2>&1 || { tail -30 "$build/build.log"; exit 1; }
bin() { find "$build" -name "$1" -type f -perm -u+x | head -1; }
runner=$(bin cvo_run_sequence) peers=$(bin cvo_peers) evaluate=$(bin cvo_evaluate)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

case "$kind" in
  tum)
    data=${2:-$CVO_ROOT/test/data/tum_fr1_xyz}
    seq=(--tum "$data")
    gt="$data/groundtruth.txt"
    eval_opts=()
    preset="$CVO_ROOT/config/tum_rgbd.yaml"
    full_cloud=(--selector grid --min-points 300000 --max-points 400000)  # every valid pixel
    methods=("ours colour|ours|--set use_color=true" "ours geometric|ours|--set use_color=false"
      "OpenCV RgbdOdometry|opencv_rgbd|" "OpenCV ICPOdometry|opencv_icp|"
      "OpenCV RgbdICPOdometry|opencv_rgbdicp|"
      "PCL GICP (full cloud, 1 cm voxels)|pcl_gicp|${full_cloud[*]}"
      "PCL NDT (full cloud, 1 cm voxels)|pcl_ndt|${full_cloud[*]}"
      "Open3D colored ICP|open3d_colored_icp|" "Open3D RGB-D odometry (hybrid)|open3d_rgbd_hybrid|")
    ;;
  kitti)
    data=${2:-$CVO_ROOT/test/data/kitti_06_stereo}
    seq=(--kitti "$data")
    gt="$data/poses.txt"
    eval_opts=(--drift-lengths 10,20,30,40,50 --gt-times "$data/times.txt" --est-times "$data/times.txt")
    preset="$CVO_ROOT/config/kitti_stereo.yaml"
    methods=("ours colour-intensity|ours|--set use_color=true"
      "ours geometric|ours|--set use_color=false"
      "PCL GICP (our stereo clouds)|pcl_gicp|--preset $preset"
      "PCL NDT (our stereo clouds)|pcl_ndt|--preset $preset")
    ;;
  *) echo "usage: $0 tum|kitti [DIR]" >&2; exit 2 ;;
esac

printf '| %-36s | %9s | %9s | %9s | %9s | %10s | %8s | %8s |\n' method "RPE mm" "RPE deg" \
  "RPE m/s" "RPE deg/s" "1s RPE mm" "ATE mm" "ms/frame"
printf '|%s|\n' "--------------------------------------|-----------|-----------|-----------|-----------|------------|----------|----------"
for entry in "${methods[@]}"; do
  IFS='|' read -r label method options <<<"$entry"
  est="$work/$method.txt"
  # shellcheck disable=SC2086
  case "$method" in
    ours) timing=$("$runner" "${seq[@]}" --preset "$preset" $options --quiet --out "$est" 2>/dev/null |
                   awk '/^  total/ {print $2}') ;;
    open3d_*) timing=$(/usr/bin/python3 "$CVO_ROOT/bench/peers/open3d_peers.py" "$data" "$method" "$est" 2>/dev/null |
                   awk '/^  frame/ {print $2}') ;;
    *) timing=$("$peers" "${seq[@]}" --method "$method" $options --out "$est" 2>/dev/null |
                awk '/^  frame/ {print $2}') ;;
  esac
  "$evaluate" --gt "$gt" --est "$est" "${eval_opts[@]}" > "$work/report.txt"
  awk -v label="$label" -v ms="$timing" '
    /^RPE frame-to-frame/ { t = $5 * 1000; r = $7; tr = $9; rr = $11 }
    /^RPE delta/ { d = ($5 == "n/a") ? -1 : $7 * 1000 }
    /^ATE rmse/ { a = $3 * 1000 }
    /^drift/ { drift = $0 }
    END { printf "| %-36s | %9.2f | %9.3f | %9.4f | %9.3f | %10.2f | %8.2f | %8.1f |\n",
                 label, t, r, tr, rr, d, a, ms
          if (drift != "" && drift !~ /n\/a/) print "  " label ": " drift > "/dev/stderr" }' \
    "$work/report.txt"
done
