#!/usr/bin/env bash
# shellcheck source-path=SCRIPTDIR
# How much of a TUM sequence's error belongs to its reference (the ground truth, or whatever the
# depth sensor gives every depth method alike): ours (TUM preset) and a depth-based peer, each
# against the ground truth and against each other (cvo_evaluate: ATE, frame-to-frame and 1 s RPE
# translation), then the "three-cornered hat": with independent errors d(A,B)^2 = e_A^2 + e_B^2
# for each of the three pairs, solved for each one's own e. An error the two estimates share
# counts as the reference's; a negative variance (printed as its signed root) means the errors
# are not independent enough for the split.
# Usage: bench/reference_share.sh [TUM_DIR] [PEER]   (defaults: the bundled fr1_xyz excerpt,
# opencv_icp; any cvo_peers method, e.g. pcl_gicp). Builds like bench/peer_table.sh.
set -euo pipefail
# shellcheck source=../scripts/env.sh
source "$(dirname "$0")/../scripts/env.sh"
# shellcheck source=peer_build.sh
source "$CVO_ROOT/bench/peer_build.sh"
data=${1:-$CVO_ROOT/test/data/tum_fr1_xyz}
peer=${2:-opencv_icp}
[ -f "$data/groundtruth.txt" ] ||
  { echo "usage: $0 [TUM_DIR] [PEER] (no groundtruth.txt in '$data')" >&2; exit 2; }

peer_build
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$runner" --tum "$data" --preset "$CVO_ROOT/config/tum_rgbd.yaml" --set backend=cpu --quiet \
  --out "$work/ours.txt" >/dev/null 2>"$work/log" || { cat "$work/log" >&2; exit 1; }
"$peers" --tum "$data" --method "$peer" --out "$work/peer.txt" >/dev/null 2>"$work/log" ||
  { cat "$work/log" >&2; exit 1; }

# "ATE f2f 1s" in mm of $2 against $1 as the reference.
errors() {
  "$evaluate" --gt "$1" --est "$2" 2>"$work/log" | awk '
    /^ATE rmse/ { ate = $3 * 1000 }
    /^RPE frame-to-frame/ { f2f = $5 * 1000 }
    /^RPE delta/ { sec = $7 * 1000 }
    END { printf "%.3f %.3f %.3f\n", ate, f2f, sec }' || { cat "$work/log" >&2; return 1; }
}
gt="$data/groundtruth.txt"
read -r -a ours_gt <<<"$(errors "$gt" "$work/ours.txt")"
read -r -a peer_gt <<<"$(errors "$gt" "$work/peer.txt")"
read -r -a ours_peer <<<"$(errors "$work/peer.txt" "$work/ours.txt")"
printf '| mm | ATE | frame to frame | 1 s RPE |\n|---|---|---|---|\n'
printf '| ours against the ground truth | %s | %s | %s |\n' "${ours_gt[@]}"
printf '| %s against the ground truth | %s | %s | %s |\n' "$peer" "${peer_gt[@]}"
printf '| ours against %s | %s | %s | %s |\n' "$peer" "${ours_peer[@]}"
for k in 0 1 2; do
  awk -v a="${ours_gt[k]}" -v b="${peer_gt[k]}" -v c="${ours_peer[k]}" 'BEGIN {
    # a^2 = o + r, b^2 = p + r, c^2 = o + p
    half = (a * a + b * b + c * c) / 2
    r = half - c * c; o = half - b * b; p = half - a * a
    printf "%s %s %s\n", signed_root(r), signed_root(o), signed_root(p) }
    function signed_root(v) { return sprintf("%.2f", v < 0 ? -sqrt(-v) : sqrt(v)) }'
done >"$work/split"
mapfile -t split <"$work/split"
read -r -a ate <<<"${split[0]}"
read -r -a f2f <<<"${split[1]}"
read -r -a sec <<<"${split[2]}"
printf '| three-cornered hat: the reference own | %s | %s | %s |\n' "${ate[0]}" "${f2f[0]}" \
  "${sec[0]}"
printf '| three-cornered hat: ours own | %s | %s | %s |\n' "${ate[1]}" "${f2f[1]}" "${sec[1]}"
printf '| three-cornered hat: %s own | %s | %s | %s |\n' "$peer" "${ate[2]}" "${f2f[2]}" \
  "${sec[2]}"
