#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# Our whole KITTI stereo frame against one full-frame OpenCV StereoSGBM disparity of the same
# pairs, as a ratio, so that the figure does not depend on the machine's speed (issue 42).
#   ours: cvo_run_sequence --kitti (the kitti_stereo preset, CPU backend): `total`, i.e.
#     OdometryPipeline::process from decoded images to a pose (stereo depth, cloud, feature
#     prior, registration, photometric stage, disparity offset), and `cpu (all threads)`, the
#     process's CPU time a frame;
#   SGBM: bench/stereo_sgbm_time, StereoSGBM::compute on the full 1226x370 pair, 128 disparities,
#     block 5, MODE_SGBM_3WAY (OpenCV's threads), decoded images in, fixed-point disparity out.
# Both time every pair of the folder but the first (which only seeds the next frame, or warms
# OpenCV's buffers), the same pairs. The two alternate in rounds (ours then SGBM, then SGBM then
# ours, ...) so that each round's pair shares the machine's minute; the table gives each round
# and, last, the median over the rounds of each column, with the ratios of those medians.
# Usage: bench/stereo_time.sh [KITTI_DIR] [ROUNDS] [-- RUNNER_OPTION...]
#   KITTI_DIR  default: $KITTI06, else ../shared/data/kitti_06_stereo beside the checkout, else
#              the bundled test/data/kitti_06_stereo (8 frames: a smoke test, not a measurement)
#   ROUNDS     default 3
#   RUNNER_OPTION...  passed to cvo_run_sequence (e.g. --set stereo_depth=dense)
# Tools: built Release without ROS in $CVO_BENCH_BUILD (default build/stereo_bench; log there).
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
data=${1:-${KITTI06:-}}
if [ -z "$data" ]; then
  data="$CVO_ROOT/../shared/data/kitti_06_stereo"
  [ -d "$data" ] || data="$CVO_ROOT/test/data/kitti_06_stereo"
fi
rounds=${2:-3}
[ $# -ge 2 ] && shift 2 || shift $#
[ "${1:-}" = "--" ] && shift
runner_options=("$@")
[ -f "$data/calib.txt" ] && [ -d "$data/image_0" ] ||
  { echo "usage: $0 [KITTI_DIR] [ROUNDS] [-- RUNNER_OPTION...] (no KITTI folder at '$data')" >&2
    exit 2; }
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS must be a positive integer" >&2; exit 2; }

build=${CVO_BENCH_BUILD:-$CVO_ROOT/build/stereo_bench}
mkdir -p "$build"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$CVO_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCVO_WITH_ROS=OFF \
    -DCVO_BUILD_TESTS=OFF >"$build/build.log" 2>&1 || { tail -30 "$build/build.log" >&2; exit 1; }
fi
cmake --build "$build" -j"$(cvo_jobs)" --target cvo_run_sequence stereo_sgbm_time \
  >>"$build/build.log" 2>&1 || { tail -30 "$build/build.log" >&2; exit 1; }
tool() { find "$build" -name "$1" -type f -perm -u+x | head -1; }
runner=$(tool cvo_run_sequence) sgbm=$(tool stereo_sgbm_time)
[ -x "$runner" ] && [ -x "$sgbm" ] || { echo "a tool is missing in $build" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# "median p95 cpu_median cores" of our total.
ours() {
  "$runner" --kitti "$data" --backend cpu --quiet ${runner_options[@]+"${runner_options[@]}"} \
    >"$work/ours.out" 2>"$work/ours.log" || { cat "$work/ours.log" >&2; return 1; }
  awk '/^  total/ {t = $2 " " $3} /^  cpu \(all threads\)/ {c = $4}
       /^cores in use/ {n = $4} END {print t, c, n}' "$work/ours.out"
}
# "median p95 cpu_median" of one full-frame SGBM.
sgbm_time() {
  "$sgbm" --kitti "$data" >"$work/sgbm.out" 2>"$work/sgbm.log" ||
    { cat "$work/sgbm.log" >&2; return 1; }
  awk '/^sgbm cpu/ {c = $3; next} /^sgbm/ {t = $2 " " $3} END {print t, c}' "$work/sgbm.out"
}

load_start=$(cut -d' ' -f1 /proc/loadavg)
rows=()
for round in $(seq 1 "$rounds"); do
  if [ $((round % 2)) -eq 1 ]; then
    o=$(ours) s=$(sgbm_time)
  else
    s=$(sgbm_time) o=$(ours)
  fi
  rows+=("$round $o $s")
  echo "round $round: ours $o, sgbm $s" >&2
done
echo "KITTI $(basename "$data"), $(cvo_jobs) cores, load average (1 min) $load_start at the" \
  "start, $(cut -d' ' -f1 /proc/loadavg) at the end;" \
  "ours: cvo_run_sequence total${runner_options[*]+ (${runner_options[*]})}; SGBM: full frame," \
  "128 disparities, block 5, 3-way"
printf '%s\n' "${rows[@]}" | awk '
  function median(a, n,    i, j, t, b) {
    for (i = 1; i <= n; ++i) b[i] = a[i]
    for (i = 2; i <= n; ++i) for (j = i; j > 1 && b[j - 1] > b[j]; --j) {
      t = b[j]; b[j] = b[j - 1]; b[j - 1] = t }
    return n % 2 ? b[(n + 1) / 2] : (b[n / 2] + b[n / 2 + 1]) / 2
  }
  function row(label, om, op, oc, cores, sm, sp, sc) {
    printf "| %-7s | %8.1f | %8.1f | %8.1f | %5.2f | %8.1f | %8.1f | %8.1f | %6.2fx | %6.2fx | %6.2fx |\n",
           label, om, op, oc, cores, sm, sp, sc, om / sm, op / sp, oc / sc
  }
  { n = NR; om[n] = $2; op[n] = $3; oc[n] = $4; co[n] = $5; sm[n] = $6; sp[n] = $7; sc[n] = $8 }
  END {
    print "| round   | ours median ms | ours p95 ms | ours cpu ms | cores | SGBM median ms | SGBM p95 ms | SGBM cpu ms | median ratio | p95 ratio | cpu ratio |"
    print "|---------|---------:|---------:|---------:|------:|---------:|---------:|---------:|--------:|--------:|--------:|"
    for (i = 1; i <= n; ++i) row(i, om[i], op[i], oc[i], co[i], sm[i], sp[i], sc[i])
    if (n > 1)
      row("median", median(om, n), median(op, n), median(oc, n), median(co, n), median(sm, n),
          median(sp, n), median(sc, n))
  }'
echo "Ratios: ours over SGBM (median over median, p95 over p95, CPU time over CPU time); the"
echo "median row takes each column's median over the rounds. CPU ms: median CPU time a frame,"
echo "all threads; cores: ours' CPU time over its wall time."
