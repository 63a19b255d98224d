#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# Moving objects: the bundled sequences with a textured board composited into every frame
# (cvo_make_dynamic: sizes, textures, speeds, distances, directions, exact or imperfect labels),
# and per case, side by side on the same frames: ours without labels, ours with the object's
# class in ignore_classes, and the OpenCV RGB-D peers on the TUM cases (no failure flag: every pose
# counts as trusted; they need depth images, so the stereo rows have none).
# Each cell: tracked/recovered/lost/restarted frames, frame-to-frame error of the trusted poses
# (mm / deg), and the silent count (trusted frames off the ground truth's step from the trusted
# frame before by > 1 deg, or by > half the step and > 2 cm; a pair across a restart is not
# judged). Ours runs with lost_frame_policy publish_nothing, so that only trusted poses are in
# its trajectory.
# Usage: bench/dynamic_table.sh [--quick] [--extra] [--stride N] [--first N] [--drop SHARE,SEED]
#                               [--check] [--no-peers] [--tum DIR] [--kitti DIR] [--bin DIR]
#   --quick     three TUM cases (the issue's person, a plain board without corners, and a
#               checkerboard: a repeating texture), labelled and not; no peers (CI)
#   --extra     more cases, made after the rules were set (other directions, a slow board, a
#               near one, the scene's texture moving along, labels spilling over, cars crossing
#               near and coming closer, a checkered truck; and two objects at once)
#   --stride N  every N-th frame (ours only: no peers)
#   --first N   from the N-th frame on (0; ours only: no peers): other pairs of frames
#   --drop SHARE,SEED  frames left out at random, as a busy driver drops them (cvo_run_sequence
#               --drop; ours only: no peers): steps of several frames at random places
#   --check     exit 1 when a run of ours has a silent failure, a labelled run loses a frame, or
#               an unlabelled run of one object up to a third of the image trusts fewer than two
#               thirds of the frames
#   --random N[,SEED]  instead of the named cases, N TUM and N/2 KITTI cases drawn at random
#               (size, distance, velocity, with the camera or not, start, texture, shape; SEED 1:
#               the same seed, the same cases on every machine): objects no rule was tuned on
#   --no-peers  skip the OpenCV peers (they need bench/peer_build.sh's build: PCL, contrib)
#   --tum, --kitti  the sequences (default: the bundled excerpts; KITTI: every frame there)
#   --bin DIR   our tools (default: build/devel/lib/cvo_odometry)
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
quick=false more_cases=false check=false peers_on=true stride=1 first=0 drop='' random=''
tum=$CVO_ROOT/test/data/tum_fr1_xyz kitti=$CVO_ROOT/test/data/kitti_06_stereo
bin=$CVO_BUILD/devel/lib/cvo_odometry
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=true peers_on=false ;;
    --extra) more_cases=true ;;
    --stride) stride=${2:-none}; [ $# -lt 2 ] || shift ;;
    --first) first=${2:-none}; [ $# -lt 2 ] || shift ;;
    --drop) drop=${2:-}; [ $# -lt 2 ] || shift ;;
    --check) check=true ;;
    --no-peers) peers_on=false ;;
    --random) random=${2:-}; [ $# -lt 2 ] || shift ;;
    --tum) tum=$2; shift ;;
    --kitti) kitti=$2; shift ;;
    --bin) bin=$2; shift ;;
    *) sed -n '3,32p' "$0" >&2; exit 2 ;;
  esac
  shift
done
[[ "$stride" =~ ^[1-9][0-9]*$ ]] ||
  { echo "dynamic_table: --stride takes a positive integer" >&2; exit 2; }
[[ "$first" =~ ^[0-9]+$ ]] ||
  { echo "dynamic_table: --first takes a frame index (0 or more)" >&2; exit 2; }
[ -z "$random" ] || [[ "$random" =~ ^[1-9][0-9]*(,[0-9]+)?$ ]] ||
  { echo "dynamic_table: --random takes a case count and an optional seed (16,1)" >&2; exit 2; }
[ "$stride" = 1 ] && [ "$first" = 0 ] && [ -z "$drop" ] || peers_on=false
drop_args=()
[ -z "$drop" ] || drop_args=(--drop "$drop")
for tool in cvo_make_dynamic cvo_run_sequence cvo_evaluate; do
  [ -x "$bin/$tool" ] || { echo "dynamic_table: no $bin/$tool (build it, or --bin DIR)" >&2; exit 2; }
done
if $peers_on; then
  # shellcheck source=peer_build.sh
  source "$CVO_ROOT/bench/peer_build.sh"
  peer_build
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# name|dataset|cvo_make_dynamic options ("A + B": B composited over A, so B is the nearer one).
# TUM fr1_xyz: the camera moves 0.37 m forward over the 37 frames, so a board that should stay
# 0.5-0.7 m away walks away from it at 0.2 m/s.
tum_cases=(
  "person: a third, blocks, across|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5"
  "plain: a third, plain|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --texture plain"
  "checker: a third, checkerboard|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --texture checker"
)
if ! $quick; then
  tum_cases+=(
    "small: a tenth, blocks|tum|--area 0.1 --depth 0.65 --velocity 0.25,0,0.2 --start 0.3,0.5"
    "large: half, blocks|tum|--area 0.5 --depth 0.65 --velocity 0.2,0,0.2 --start 0.3,0.5"
    "scene: a third, the scene's texture|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --texture scene"
    "stripes: a third, ellipse|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --texture stripes --shape ellipse"
    "fast: a third, 0.6 m/s across|tum|--area 0.33 --depth 0.65 --velocity 0.6,0,0.2 --start 0.15,0.5"
    "towards: approaching from 1.2 m|tum|--area 0.12 --depth 1.2 --velocity 0,0,-0.4 --start 0.5,0.45"
    "far: a fifth at 0.9 m|tum|--area 0.2 --depth 0.9 --velocity 0.3,0,0.25 --start 0.25,0.5"
    "along: a quarter moving with the camera|tum|--area 0.25 --depth 0.6 --with-camera --velocity 0.1,0,0 --start 0.3,0.55"
    "labels 4 px short: person|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --label-error 4"
    "person's labels, no object|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --labels-only"
    "large's labels, no object|tum|--area 0.5 --depth 0.65 --velocity 0.2,0,0.2 --start 0.3,0.5 --labels-only"
  )
fi
if $more_cases; then
  tum_cases+=(
    "leftward: a third, from the right|tum|--area 0.3 --depth 0.7 --velocity -0.3,0,0.25 --start 0.8,0.5"
    "diagonal: a quarter, checkerboard, down and left|tum|--area 0.25 --depth 0.6 --velocity -0.2,0.15,0.25 --start 0.7,0.3 --texture checker"
    "slow: a third at 0.08 m/s|tum|--area 0.3 --depth 0.65 --velocity 0.08,0,0.2 --start 0.3,0.5"
    "near: a fifth at 0.4 m, ellipse|tum|--area 0.2 --depth 0.4 --velocity 0.3,0,0 --start 0.2,0.5 --shape ellipse"
    "scene along: the scene's texture, with the camera|tum|--area 0.25 --depth 0.6 --with-camera --velocity 0.1,0,0 --start 0.3,0.55 --texture scene"
    "labels 6 px over: person|tum|--area 0.33 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5 --label-error -6"
    "two: a fifth back, a third across in front|tum|--area 0.2 --depth 0.8 --velocity -0.3,0,0.25 --start 0.8,0.5 --texture checker --seed 5 + --area 0.3 --depth 0.65 --velocity 0.25,0,0.2 --start 0.2,0.5"
  )
fi
kitti_cases=()
if ! $quick; then
  kitti_cases=(
    "van along: a sixth, 9 m, drifting|kitti|--area 0.16 --depth 9 --with-camera --velocity 1.9,0,0 --start 0.35,0.6"
    "van crossing: 30 m ahead, 8 m/s|kitti|--area 0.05 --depth 30 --velocity 8,0,0 --start 0.2,0.6"
    "truck along: a third, 8 m|kitti|--area 0.3 --depth 8 --with-camera --velocity 1,0,0 --start 0.45,0.6"
    "overtaking: a car pulling away|kitti|--area 0.15 --depth 7 --with-camera --velocity 0,0,3 --start 0.6,0.62"
    "truck's labels, no object|kitti|--area 0.3 --depth 8 --with-camera --velocity 1,0,0 --start 0.45,0.6 --labels-only"
  )
fi
if $more_cases; then
  kitti_cases+=(
    "car crossing 15 m ahead, leftward|kitti|--area 0.12 --depth 15 --velocity -6,0,0 --start 0.7,0.6"
    "oncoming car from 25 m|kitti|--area 0.08 --depth 25 --velocity 0,0,-8 --start 0.4,0.6"
    "checkered truck along, leftward|kitti|--area 0.3 --depth 8 --with-camera --velocity -1,0,0 --start 0.55,0.6 --texture checker"
    "two: a car crossing, a van along in front|kitti|--area 0.08 --depth 15 --velocity -6,0,0 --start 0.7,0.6 --seed 5 + --area 0.16 --depth 9 --with-camera --velocity 1.9,0,0 --start 0.35,0.6"
  )
fi

if [ -n "$random" ]; then
  # A linear congruential generator in shell arithmetic: the same seed draws the same cases
  # whatever the machine's awk or shell random source.
  draws=${random%%,*} lcg=1
  [ "$draws" = "$random" ] || lcg=${random#*,}
  uniform() {  # VAR LO HI DECIMALS: VAR set to a number drawn from [LO, HI]
    lcg=$(((lcg * 1103515245 + 12345) % 2147483648))
    printf -v "$1" '%s' "$(awk -v r="$lcg" -v lo="$2" -v hi="$3" -v d="$4" \
      'BEGIN { printf("%." d "f", lo + (hi - lo) * r / 2147483648) }')"
  }
  pick() {  # VAR WORD...: VAR set to one of the words
    local var=$1
    shift
    lcg=$(((lcg * 1103515245 + 12345) % 2147483648))
    local words=("$@")
    printf -v "$var" '%s' "${words[$(((lcg / 65536) % ${#words[@]}))]}"
  }
  # Ranges: TUM objects at 0.45-1.2 m covering 10-45 % of the image, walking (up to 0.6 m/s,
  # any direction in the image, towards or away) or carried along with the camera (a fifth);
  # KITTI vehicles at 6-20 m (a truck's third of the image at 8 m at most), crossing or
  # oncoming, or driving along (half).
  random_case() {  # KIND INDEX: the case in `drawn` (no subshell: the generator moves on)
    local kind=$1 index=$2 area depth vx vy vz u v texture shape seed along name with=""
    if [ "$kind" = tum ]; then
      uniform area 0.1 0.45 2
      uniform depth 0.45 1.2 2
      uniform along 0 1 2
      if awk -v a="$along" 'BEGIN { exit !(a < 0.2) }'; then
        with="--with-camera "
        uniform vx -0.15 0.15 2
        uniform vy -0.05 0.05 2
        uniform vz -0.05 0.05 2
      else
        uniform vx 0.05 0.6 2
        pick vx "$vx" "-$vx"
        uniform vy -0.15 0.15 2
        uniform vz -0.3 0.3 2
      fi
      uniform u 0.15 0.85 2
      uniform v 0.35 0.65 2
    else
      uniform depth 6 20 1
      # A vehicle's size: up to a truck's third of the image at 8 m, less further away.
      local largest
      largest=$(awk -v z="$depth" 'BEGIN { a = 0.3 * (8 / z) ^ 2; print (a > 0.3 ? 0.3 : a) }')
      uniform area 0.02 "$largest" 2
      uniform along 0 1 2
      vy=0
      if awk -v a="$along" 'BEGIN { exit !(a < 0.5) }'; then
        with="--with-camera "
        uniform vx -2.5 2.5 1
        uniform vz -3 3 1
      else
        uniform vx 2 10 1
        pick vx "$vx" "-$vx"
        uniform vz -8 2 1
      fi
      uniform u 0.2 0.8 2
      uniform v 0.5 0.65 2
    fi
    pick texture plain stripes checker blocks scene
    pick shape rect ellipse
    uniform seed 1 99 0
    name="random $kind $index: $texture $shape, $area of the image at $depth m, $vx,$vy,$vz m/s"
    [ -z "$with" ] || name="$name with the camera"
    drawn="$name|$kind|--area $area --depth $depth $with--velocity $vx,$vy,$vz --start $u,$v --texture $texture --shape $shape --seed $seed"
  }
  tum_cases=() kitti_cases=()
  for ((k = 1; k <= draws; k++)); do
    random_case tum "$k"
    tum_cases+=("$drawn")
  done
  for ((k = 1; k <= draws / 2; k++)); do
    random_case kitti "$k"
    kitti_cases+=("$drawn")
  done
fi

# "trusted/recovered/lost|mm|deg|silent" of a runner log.
# The error is the trusted pairs' the silent count judges: none across a restart, where the
# pose holds while the camera moved on.
ours_cell() {
  awk '/^tracking:/ { t = $2; r = $4; l = $6; x = $8 }
       /^trusted frame-to-frame/ && !done { n = substr($3, 2) + 0; mm = $9 * 1000; deg = $11
                                            done = 1 }
       /^silent failures:/ { s = $3 }
       END { if (done && n > 0) printf "%d/%d/%d/%d|%.2f|%.3f|%s\n", t, r, l, x, mm, deg, s
             else printf "%d/%d/%d/%d|-|-|%d\n", t, r, l, x, s }' "$1"
}
# "mm|deg|silent" of a cvo_evaluate --all-trusted log.
peer_cell() {
  awk '/^RPE frame-to-frame/ { mm = $5 * 1000; deg = $7 }
       /^silent failures:/ { s = $3 }
       END { printf "%.2f|%.3f|%s\n", mm, deg, s }' "$1"
}

# The OpenCV peers' cells, "mm|deg|silent|mm|deg|silent", on a sequence (none without peers).
peer_cells() {
  local kind=$1 dir=$2 gt=$3 cells=() method
  $peers_on || return 0
  # OpenCV's RGB-D odometry needs a depth image: on stereo cases the cells say "-".
  [ "$kind" = kitti ] && { echo "-|-|-|-|-|-"; return 0; }
  for method in opencv_rgbd opencv_icp; do
    "$peers" "--$kind" "$dir" --method "$method" --out "$work/$method.txt" \
      >"$work/$method.out" 2>"$work/$method.log" || { cat "$work/$method.log" >&2; exit 1; }
    local times=()
    [ "$kind" = kitti ] && times=(--gt-times "$dir/times.txt" --est-times "$dir/times.txt")
    "$evaluate" --gt "$gt" --est "$work/$method.txt" --all-trusted "${times[@]}" \
      >"$work/$method.eval" 2>&1 || { cat "$work/$method.eval" >&2; exit 1; }
    cells+=("$(peer_cell "$work/$method.eval")")
  done
  (IFS='|'; echo "${cells[*]}")
}

failed=0
rows=()
run_case() {
  local name=$1 kind=$2 options=$3 dir=$work/case
  rm -rf "$dir"
  local source=$tum gt object_options objects=0
  [ "$kind" = kitti ] && source=$kitti
  [ -n "$options" ] || { echo "dynamic_table: $name: no object" >&2; exit 2; }
  # One object after the other, each made from the folder with those before it.
  while [ -n "$options" ]; do
    object_options=${options%% + *}
    if [ "$object_options" = "$options" ]; then options=; else options=${options#* + }; fi
    objects=$((objects + 1))
    rm -rf "$dir.$objects"
    # shellcheck disable=SC2086  # the options are words
    "$bin/cvo_make_dynamic" "--$kind" "$source" --out "$dir.$objects" $object_options \
      >"$work/make.log" 2>&1 || { cat "$work/make.log" >&2; exit 1; }
    source=$dir.$objects
    # The share and motion columns: the first object's.
    if [ "$objects" = 1 ]; then cp "$work/make.log" "$work/first.log"; fi
  done
  mv "$source" "$dir"
  rm -rf "$dir".*
  local covers
  covers=$(sed -n 's/.*covers \([0-9.]*\) % of the first image (median \([0-9.]*\) %), moves \([0-9.]*\) px.*/\1-\2 %, \3 px\/frame/p' "$work/first.log")
  gt=$dir/groundtruth.txt
  [ "$kind" = kitti ] && gt=$dir/poses.txt
  local ours=() variant
  for variant in unlabelled labelled; do
    local extra=()
    [ "$variant" = labelled ] &&
      extra=(--segmentation "$dir/labels" --semantic-classes 2 --ignore-classes 1)
    # A run that trusts fewer than two frames has no error to evaluate: its cell says so.
    "$bin/cvo_run_sequence" "--$kind" "$dir" --gt "$gt" --quiet --set backend=cpu \
      --stride "$stride" --first "$first" "${drop_args[@]}" --lost-frame-policy publish_nothing \
      "${extra[@]}" \
      >"$work/$variant.log" 2>&1 ||
      grep -q "^tracking:" "$work/$variant.log" || { tail -5 "$work/$variant.log" >&2; exit 1; }
    ours+=("$(ours_cell "$work/$variant.log")")
  done
  rows+=("$name|$covers|${ours[0]}|${ours[1]}|$(peer_cells "$kind" "$dir" "$gt")")
  if $check; then
    local silent_u silent_l lost_l counts_u trusted_u judged_u share
    silent_u=$(echo "${ours[0]}" | cut -d'|' -f4)
    silent_l=$(echo "${ours[1]}" | cut -d'|' -f4)
    lost_l=$(echo "${ours[1]}" | cut -d'|' -f1 | cut -d/ -f3)
    if [ "$silent_u" != 0 ] || [ "$silent_l" != 0 ] || [ "$lost_l" != 0 ]; then
      echo "dynamic_table: $name: silent failures $silent_u (no labels) / $silent_l (labels)," \
        "labelled frames lost $lost_l" >&2
      failed=1
    fi
    # Unlabelled, an object up to a third of the image: two thirds of the frames trusted.
    share=$(echo "$covers" | sed 's/^\([0-9.]*\).*/\1/')
    counts_u=$(echo "${ours[0]}" | cut -d'|' -f1)
    trusted_u=$(echo "$counts_u" | awk -F/ '{ print $1 + $2 }')
    judged_u=$(echo "$counts_u" | awk -F/ '{ print $1 + $2 + $3 }')
    if [ "$objects" = 1 ] && awk -v s="$share" 'BEGIN { exit !(s <= 40) }' &&
      [ $((3 * trusted_u)) -lt $((2 * judged_u)) ]; then
      echo "dynamic_table: $name: without labels $trusted_u of $judged_u frames trusted" \
        "(fewer than two thirds)" >&2
      failed=1
    fi
  fi
}

# The static sequences first: the figures each case is compared with.
static_row() {
  local kind=$1 source=$2 gt=$3
  "$bin/cvo_run_sequence" "--$kind" "$source" --gt "$gt" --quiet --set backend=cpu \
    --stride "$stride" --first "$first" "${drop_args[@]}" --lost-frame-policy publish_nothing \
    >"$work/static.log" 2>&1 ||
    { tail -5 "$work/static.log" >&2; exit 1; }
  local cell
  cell=$(ours_cell "$work/static.log")
  rows+=("$kind without an object|-|$cell|-|-|-|-|$(peer_cells "$kind" "$source" "$gt")")
}

static_row tum "$tum" "$tum/groundtruth.txt"
for entry in "${tum_cases[@]}"; do
  IFS='|' read -r name kind options <<<"$entry"
  run_case "$name" "$kind" "$options"
done
if [ ${#kitti_cases[@]} -gt 0 ]; then
  static_row kitti "$kitti" "$kitti/poses.txt"
  for entry in "${kitti_cases[@]}"; do
    IFS='|' read -r name kind options <<<"$entry"
    run_case "$name" "$kind" "$options"
  done
fi

strided=$([ "$stride" = 1 ] || echo ", stride $stride")$([ "$first" = 0 ] || echo ", from frame $first")$([ -z "$drop" ] || echo ", frames dropped (--drop $drop)")
echo "Moving objects ($(basename "$tum"), $(basename "$kitti")$strided): per run tracked/recovered/lost/" \
  "restarted frames, frame-to-frame error of trusted poses (mm / deg), silent failures"
header="| case | object: share of image, motion | ours, no labels | ours, labelled |"
rule="|---|---|---|---|"
if $peers_on; then
  header="$header OpenCV RgbdOdometry | OpenCV ICPOdometry |"
  rule="$rule---|---|"
fi
echo "$header"
echo "$rule"
for row in "${rows[@]}"; do
  IFS='|' read -r -a f <<<"$row"
  line="| ${f[0]} | ${f[1]} | ${f[2]}: ${f[3]} mm / ${f[4]} deg, ${f[5]} silent |"
  if [ "${f[6]}" = "-" ]; then
    line="$line - |"
  else
    line="$line ${f[6]}: ${f[7]} mm / ${f[8]} deg, ${f[9]} silent |"
  fi
  if $peers_on && [ "${f[10]:-}" = "-" ]; then
    line="$line - | - |"
  elif $peers_on; then
    line="$line ${f[10]:-?} mm / ${f[11]:-?} deg, ${f[12]:-?} silent | ${f[13]:-?} mm / ${f[14]:-?} deg, ${f[15]:-?} silent |"
  fi
  echo "$line"
done
exit "$failed"
