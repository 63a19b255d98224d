#!/usr/bin/env bash
# Tables for doc/ that no bench script prints, made from the tools' own output (doc/regenerate.sh
# runs them from the pages' generated blocks).
#
# Usage:
#   doc/tables.sh runs tum|kitti DIR 'LABEL|RUNNER OPTIONS' ...
#       one cvo_run_sequence run per row (CPU backend, the dataset's preset, ground truth from the
#       folder): tracking counts, silent failures, frame-to-frame RPE, ATE, KITTI drift over
#       10-50 m and the estimated disparity offset, the feature prior alone, median ms
#   doc/tables.sh stages tum|kitti DIR [RUNNER OPTIONS]
#       the runner's time per stage (median and p95 ms a frame) and the cores it got
#   doc/tables.sh headline [PAGE]
#       README's headline table: ours and the best peer in translation and in rotation, read
#       from the peer tables of PAGE (default doc/accuracy.md)
#   doc/tables.sh essential KITTI_DIR [STRIDE...]
#       rotation error per step (rms deg) of ours (cvo_run_sequence, CPU) and of a third estimator
#       using neither depth nor CVO (essential_rotation: five-point essential matrix of tracked
#       corners), against the ground truth and each other, over all pairs and from frame 12
#   doc/tables.sh stderr-last COMMAND [ARG...]
#       COMMAND's standard output, then its standard error (e.g. bench/peer_table.sh's drift
#       lines, which would otherwise land inside its table); COMMAND's exit status
#   doc/tables.sh machine
#       the machine the timing tables ran on: CPU model, cores, load average
# Tools from BIN (default: $ROS_BUILD/devel/lib/cvo_odometry, ROS_BUILD default build/: what
# scripts/test.sh and scripts/demo.sh build).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=../scripts/env.sh
source "$root/scripts/env.sh"
bin="${BIN:-${ROS_BUILD:-$root/build}/devel/lib/cvo_odometry}"

usage() {
  sed -n '4,24p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
runner() {
  [ -x "$bin/cvo_run_sequence" ] || { echo "no $bin/cvo_run_sequence: build first" >&2; exit 1; }
  "$bin/cvo_run_sequence" "$@"
}
# The sequence options of a run on DIR: its ground truth, and KITTI's drift lengths.
sequence() {
  local kind=$1 dir=$2
  case "$kind" in
    tum) echo "--tum $dir --gt $dir/groundtruth.txt" ;;
    kitti) echo "--kitti $dir --gt $dir/poses.txt --drift-lengths 10,20,30,40,50" ;;
    *) usage ;;
  esac
}

runs() {
  [ $# -ge 3 ] || usage
  local kind=$1 dir=$2
  shift 2
  local seq
  seq=$(sequence "$kind" "$dir")
  echo "$kind $(basename "$dir") (cvo_run_sequence $seq --backend cpu, the dataset's preset)"
  if [ "$kind" = kitti ]; then
    echo "| run | tracked / recovered / lost / restarts | silent | ours mm / deg a frame | ATE mm | drift % | disparity offset px (estimated / in use) | prior alone mm / deg | total ms |"
    echo "|---|---|---|---|---|---|---|---|---|"
  else
    echo "| run | tracked / recovered / lost / restarts | silent | ours mm / deg a frame | ATE mm | 1 s RPE mm | prior alone mm / deg | total ms |"
    echo "|---|---|---|---|---|---|---|---|"
  fi
  local entry label options out
  out=$(mktemp)
  for entry in "$@"; do
    label=${entry%%|*}
    options=${entry#*|}
    [ "$options" != "$entry" ] || options=""
    # shellcheck disable=SC2086  # the options are words on purpose
    if ! runner $seq --backend cpu --quiet $options >"$out" 2>&1; then
      echo "| $label | failed: $(grep -m1 -iE 'error|cvo_run_sequence:' "$out" | tail -1) |"
      continue
    fi
    awk -v label="$label" -v kind="$kind" '
      /^tracking:/ { counts = $2 " / " $4 " / " $6 " / " $8 }
      /^silent failures:/ { silent = $3 }
      /^feature prior alone/ { prior = 1 }
      /^ATE rmse/ && !prior { ate = $3 * 1000 }
      /^RPE frame-to-frame/ { if (prior) { pt = $5 * 1000; pr = $7 } else { t = $5 * 1000; r = $7 } }
      /^RPE delta/ && !prior { d = ($5 == "n/a") ? "n/a" : sprintf("%.1f", $7 * 1000) }
      /^drift/ && !prior { drift = ($0 ~ /n\/a/) ? "n/a" : $(NF - 3) }
      /^disparity offset: estimated/ { est = $4; use = ($14 == "use") ? $15 : $17 " (the start)" }
      /^  total/ { ms = $2 }
      END {
        prior_cell = (pt == "") ? "-" : sprintf("%.2f / %.4f", pt, pr)
        if (kind == "kitti")
          printf "| %s | %s | %s | %.2f / %.4f | %.1f | %s | %s / %s | %s | %.1f |\n", label, counts,
                 silent, t, r, ate, drift, (est == "" ? "-" : est), (use == "" ? "-" : use),
                 prior_cell, ms
        else
          printf "| %s | %s | %s | %.2f / %.4f | %.2f | %s | %s | %.1f |\n", label, counts, silent,
                 t, r, ate, d, prior_cell, ms
      }' "$out"
  done
  rm -f "$out"
}

stages() {
  [ $# -ge 2 ] || usage
  local kind=$1 dir=$2
  shift 2
  local out
  out=$(mktemp)
  # shellcheck disable=SC2046  # the sequence options are words on purpose
  runner $(sequence "$kind" "$dir") --backend cpu --quiet "$@" >"$out" 2>&1 ||
    { cat "$out" >&2; rm -f "$out"; exit 1; }
  echo "$kind $(basename "$dir"): cvo_run_sequence --backend cpu${*:+ $*}, ms a frame"
  echo "| stage | median | p95 |"
  echo "|---|---|---|"
  awk '/^timing/ { on = 1; next } on && /^  / { name = $0; sub(/^  /, "", name);
         sub(/ +[0-9.]+ +[0-9.]+$/, "", name); printf "| %s | %s | %s |\n", name, $(NF - 1), $NF; next }
       on { on = 0 } /^cores in use/ { print ""; print $1, $2, $3, $4 }' "$out"
  rm -f "$out"
}

headline() {
  local page=${1:-$root/doc/accuracy.md}
  echo "| sequence | ours: mm / deg a frame | best peer in translation | best peer in rotation |"
  echo "|---|---|---|---|"
  python3 - "$page" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
blocks = re.findall(r"<!-- generated: (?:doc/tables\.sh stderr-last )?bench/peer_table\.sh (tum|kitti)\b"
                    r"([^>]*)-->\n(.*?)<!-- end generated -->",
                    text, re.S)
kinds = {"tum": "TUM", "kitti": "KITTI"}
cameras = {"tum": "RGB-D", "kitti": "stereo"}
done = set()
for kind, args, body in blocks:
    if "--stride" in args or kind in done:
        continue
    done.add(kind)
    rows = [[c.strip() for c in l.strip().strip("|").split("|")] for l in body.splitlines()
            if l.startswith("| ") and not l.startswith("| method")]
    rows = [r for r in rows if len(r) >= 3 and re.match(r"^[0-9.]+$", r[1])]
    folder = body.split()[1].rstrip(",")  # the table's first line: "KIND FOLDER, --stride 1: ..."
    ours = rows[0]
    peers = [r for r in rows if not r[0].startswith(("ours", "feature prior"))]
    t = min(peers, key=lambda r: float(r[1]))
    r = min(peers, key=lambda r: float(r[2]))
    print(f"| {kinds[kind]} {folder} ({cameras[kind]}) | **{ours[1]} / {ours[2]}** | {t[0]}: {t[1]} / {t[2]} | "
          f"{r[0]}: {r[1]} / {r[2]} |")
if not done:
    sys.exit(f"no bench/peer_table.sh tables in {sys.argv[1]}")
PY
}

essential() {
  [ $# -ge 1 ] || usage
  local dir=$1 n f line
  shift
  [ $# -gt 0 ] || set -- 1 2 3
  echo "kitti $(basename "$dir"): rotation error per step, rms deg (essential_rotation --from 12)"
  echo "| stride | pairs | essential - truth | ours - truth | essential - ours | pairs from frame 12 | essential - truth | ours - truth |"
  echo "|---|---|---|---|---|---|---|---|"
  f=$(mktemp)
  for n in "$@"; do
    runner --kitti "$dir" --backend cpu --quiet --stride "$n" --format kitti --out "$f" >/dev/null 2>&1 ||
      { echo "| $n | the run failed |"; continue; }
    line=$("$bin/essential_rotation" --kitti "$dir" --stride "$n" --estimate "$f" --from 12 | grep '^rms' |
      paste -sd' ')
    # "rms over P pairs: essential - truth A, estimate - truth B, essential - estimate C deg rms
    #  over the Q pairs from frame 12: essential - truth D, estimate - truth E deg"
    awk -v n="$n" '{ gsub(/,/, "")
      printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", n, $3, $8, $12, $16, $21, $29, $33 }' <<<"$line"
  done
  rm -f "$f"
}

stderr_last() {
  [ $# -ge 1 ] || usage
  local err rc=0
  err=$(mktemp)
  "$@" 2>"$err" || rc=$?
  cat "$err"
  rm -f "$err"
  return "$rc"
}

machine() {
  local model
  model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
  echo "machine: ${model:-unknown CPU}, $(nproc) cores, load average at start $(cut -d' ' -f1-3 /proc/loadavg)"
}

[ $# -ge 1 ] || usage
command=$1
shift
case "$command" in
  runs) runs "$@" ;;
  stages) stages "$@" ;;
  headline) headline "$@" ;;
  essential) essential "$@" ;;
  stderr-last) stderr_last "$@" ;;
  machine) machine ;;
  *) usage ;;
esac
