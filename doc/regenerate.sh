#!/usr/bin/env bash
# Regenerates the tables of README.md and doc/*.md from the scripts that measure them. Each
# generated block of a page is
#     <!-- generated: COMMAND -->
#     ...COMMAND's standard output...
#     <!-- end generated -->
# and is replaced by a new run of COMMAND (bash, in the repository root): its output as it is,
# but for a blank line put between a markdown table and text that follows it (which would
# otherwise read as a row). "<!-- generated text: COMMAND -->" puts the output in a ```text
# block, for output in plain columns. A command that fails
# (e.g. no KITTI folder, no GPU) leaves its block as it was; the script then says which and exits 1.
# Nothing outside the blocks is touched: prose that quotes a figure names its table.
#
# Usage: doc/regenerate.sh [--list] [--only TEXT] [PAGE...]
#   PAGE     accuracy, speed, gpu, large-motions, design, testing, ... (doc/PAGE.md) or README;
#            default: every doc page, then README (its headline table is read from
#            doc/accuracy.md's tables, so regenerate accuracy first)
#   --only TEXT  only the blocks whose command contains TEXT (e.g. --only frame_time.sh)
#   --list   print each page's blocks and commands, run nothing
# The commands see these variables (set them to use other folders):
#   TUM      a TUM RGB-D folder (default: the bundled fr1_xyz excerpt, test/data/tum_fr1_xyz)
#   KITTI06  KITTI odometry sequence 06, frames 0-50, grey stereo (image_0, image_1, calib.txt,
#            times.txt, poses.txt: frames 000000-000050 of KITTI's own download; the repository
#            bundles frames 0-7 only); default ../shared/data/kitti_06_stereo beside the checkout
#   ROS_BUILD  a build of this package with ROS (default build/, as scripts/test.sh and
#            scripts/demo.sh make it); BIN its tools ($ROS_BUILD/devel/lib/cvo_odometry)
# The bench scripts build their own tools (bench/peer_build.sh: build/peers, Release, no ROS).
# Timing tables (doc/speed.md, the ms columns elsewhere) are the machine's as much as the code's:
# regenerate them on a quiet machine (doc/speed.md's first table says which machine ran them).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
# shellcheck source=../scripts/env.sh
source scripts/env.sh  # Debian's python3 and ROS tools first, as every script here
export TUM="${TUM:-test/data/tum_fr1_xyz}"
export KITTI06="${KITTI06:-../shared/data/kitti_06_stereo}"
export ROS_BUILD="${ROS_BUILD:-build}"
export BIN="${BIN:-$ROS_BUILD/devel/lib/cvo_odometry}"

usage() { echo "usage: $0 [--list] [--only TEXT] [PAGE...]" >&2; exit 2; }
list=false only="" pages=()
while [ $# -gt 0 ]; do
  case "$1" in
    --list) list=true ;;
    --only) [ $# -ge 2 ] || usage; only=$2; shift ;;
    -h|--help) usage ;;
    -*) usage ;;
    README|README.md) pages+=(README.md) ;;
    *) f="doc/${1%.md}.md"; [ -f "$f" ] || { echo "no page $f" >&2; exit 2; }; pages+=("$f") ;;
  esac
  shift
done
if [ ${#pages[@]} -eq 0 ]; then
  for f in doc/*.md; do pages+=("$f"); done
  pages+=(README.md)
fi

export CVO_REGENERATE_LIST=$list CVO_REGENERATE_ONLY=$only
status=0
for page in "${pages[@]}"; do
  python3 - "$page" <<'PY' || status=1
import os, subprocess, sys, time

page = sys.argv[1]
begins, end = ("<!-- generated: ", "<!-- generated text: "), "<!-- end generated -->"
listing = os.environ["CVO_REGENERATE_LIST"] == "true"
only = os.environ["CVO_REGENERATE_ONLY"]
with open(page) as f:
    lines = f.read().split("\n")
out, failed, i = [], [], 0
while i < len(lines):
    line = lines[i]
    out.append(line)
    i += 1
    begin = next((b for b in begins if line.startswith(b)), None)
    if begin is None or not line.endswith(" -->"):
        continue
    command = line[len(begin):-len(" -->")]
    j = i
    while j < len(lines) and lines[j] != end:
        j += 1
    if j == len(lines):
        sys.exit(f"{page}: no '{end}' after '{line}'")
    old = lines[i:j]
    if listing or (only and only not in command):
        if listing:
            print(f"{page}: {command}")
        out.extend(old)
    else:
        start = time.time()
        print(f"{page}: {command} ...", file=sys.stderr, flush=True)
        run = subprocess.run(["bash", "-c", command], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        took = time.time() - start
        if run.returncode != 0:
            why = (run.stderr.strip().splitlines() or ["(no message)"])[-1]
            print(f"{page}: FAILED (exit {run.returncode}, {took:.0f} s), block kept: {command}: "
                  f"{why}", file=sys.stderr)
            failed.append(command)
            out.extend(old)
        else:
            print(f"{page}: done in {took:.0f} s", file=sys.stderr)
            new = run.stdout.rstrip("\n").split("\n")
            if begin == begins[1]:
                new = ["```text"] + new + ["```"]
            else:
                spaced = []
                for k, text in enumerate(new):
                    spaced.append(text)
                    following = new[k + 1] if k + 1 < len(new) else ""
                    if text.startswith("|") and following and not following.startswith("|"):
                        spaced.append("")
                new = spaced
            out.extend(new)
    out.append(end)
    i = j + 1
if not listing:
    with open(page, "w") as f:
        f.write("\n".join(out))
sys.exit(1 if failed else 0)
PY
done
exit $status
