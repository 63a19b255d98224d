#!/usr/bin/env bash
# cvo_run_sequence end to end on the fixtures. TUM fr1_xyz (the TUM preset: geometric CVO and the
# photometric rotation stage): frame-to-frame RPE below the paper's baselines PCL GICP / NDT /
# Open3D colored ICP in translation (best: GICP 3.60 mm) and in rotation (best: colored ICP
# 0.348 deg), which also puts it below every geometric peer (ICPOdometry 0.438 deg); README's
# peer table (the runner measured 1.87 mm and 0.172 deg).
# KITTI 06 frames 0-7 (stereo): RPE below 5 cm and 0.15 deg per frame (the runner measured 2.1 cm
# and 0.065 deg over 51 frames). Also: trajectory files, the plot and a clear error.
set -euo pipefail
runner=$1
root=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
rpe() { grep '^RPE frame-to-frame' "$1" | awk -v k="$2" '{ print (k == "m") ? $5 : $7 }'; }

tum="$root/test/data/tum_fr1_xyz"
"$runner" --tum "$tum" --preset "$root/config/tum_rgbd.yaml" --backend cpu --quiet \
  --gt "$tum/groundtruth.txt" --out "$work/tum.txt" --plot "$work/tum.png" | tee "$work/tum_report.txt"
t=$(rpe "$work/tum_report.txt" m) r=$(rpe "$work/tum_report.txt" deg)
awk -v t="$t" 'BEGIN { exit !(t < 0.00360) }' || fail "TUM RPE $t m, bound 0.00360"
awk -v r="$r" 'BEGIN { exit !(r < 0.348) }' || fail "TUM RPE $r deg, bound 0.348"
[ "$(grep -vc '^#' "$work/tum.txt")" = 37 ] || fail "TUM trajectory should have 37 poses"
[ -s "$work/tum.png" ] || fail "no plot written"
# The cores a run got (bench/load_time.sh reads them): some CPU time is always spent.
cores=$(awk '/^cores in use:/ { print $4 }' "$work/tum_report.txt")
awk -v c="$cores" 'BEGIN { exit !(c > 0) }' || fail "no 'cores in use' figure: '$cores'"

kitti="$root/test/data/kitti_06_stereo"
"$runner" --kitti "$kitti" --preset "$root/config/kitti_stereo.yaml" --backend cpu --quiet \
  --gt "$kitti/poses.txt" --out "$work/kitti.txt" | tee "$work/kitti_report.txt"
t=$(rpe "$work/kitti_report.txt" m) r=$(rpe "$work/kitti_report.txt" deg)
awk -v t="$t" 'BEGIN { exit !(t < 0.05) }' || fail "KITTI RPE $t m, bound 0.05"
awk -v r="$r" 'BEGIN { exit !(r < 0.15) }' || fail "KITTI RPE $r deg, bound 0.15"
[ "$(awk 'NF == 12' "$work/kitti.txt" | wc -l)" = 8 ] || fail "KITTI trajectory: 8 rows of 12"

if "$runner" --tum "$tum" --kitti "$kitti" 2>"$work/err.txt"; then fail "two sequences accepted"; fi
grep -q "give one sequence" "$work/err.txt" || fail "unclear error: $(cat "$work/err.txt")"
# A repeated option is refused, not half dropped (a second --set once replaced the first).
if "$runner" --tum "$tum" --set backend=cpu --set num_threads=1 2>"$work/err.txt"; then
  fail "a repeated --set accepted"
fi
grep -q "given twice" "$work/err.txt" || fail "unclear error: $(cat "$work/err.txt")"
# --drop: frames left out at random, the same ones for the same seed, the first always kept.
for run in a b; do
  "$runner" --tum "$tum" --backend cpu --quiet --last 12 --drop 0.5,7 --out "$work/drop_$run.txt" \
    >/dev/null 2>&1 || fail "--drop 0.5,7 did not run"
done
kept=$(grep -vc '^#' "$work/drop_a.txt")
[ "$kept" -gt 1 ] && [ "$kept" -lt 13 ] || fail "--drop 0.5 kept $kept of 13 frames"
cmp -s <(awk '!/^#/ { print $1 }' "$work/drop_a.txt") <(awk '!/^#/ { print $1 }' "$work/drop_b.txt") ||
  fail "--drop 0.5,7 left out other frames on a second run"
first=$(awk 'NR == 1 { print $3 }' "$tum/associations.txt")  # the depth stamps the poses
[ "$(awk '!/^#/ { print $1; exit }' "$work/drop_a.txt")" = "$first" ] ||
  fail "--drop left out the first frame"
if "$runner" --tum "$tum" --drop 1 2>"$work/err.txt"; then fail "--drop 1 accepted"; fi
grep -q "a share in \[0, 1)" "$work/err.txt" || fail "unclear error: $(cat "$work/err.txt")"
echo "cvo_run_sequence: all checks passed"
