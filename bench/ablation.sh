#!/usr/bin/env bash
# Accuracy levers on the bundled TUM fr1_xyz excerpt: each line of the table is one
# cvo_run_sequence run (frame-to-frame RPE per frame, ATE, registration ms median).
# Usage: bench/ablation.sh [BUILD_DIR] [CONFIG_FILE]; CONFIG_FILE lines: "label | runner options".
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
configs="${2:-$root/bench/ablation_tum.txt}"
runner="$build/devel/lib/cvo_odometry/cvo_run_sequence"
data="$root/test/data/tum_fr1_xyz"
printf '| %-58s | %9s | %9s | %8s | %8s |\n' "configuration" "RPE mm" "RPE deg" "ATE mm" "reg ms"
printf '|%s|%s|%s|%s|%s|\n' "$(printf -- '-%.0s' {1..60})" "-----------" "-----------" "----------" "----------"
while IFS='|' read -r label options; do
  [[ -z "${label// }" || "$label" == \#* ]] && continue
  # shellcheck disable=SC2086
  out=$("$runner" --tum "$data" --preset "$root/config/tum_rgbd.yaml" --quiet \
    --gt "$data/groundtruth.txt" $options 2>&1) || { echo "failed: $label: $out" >&2; continue; }
  awk -v label="$(echo "$label" | xargs)" '
    # The first of each: ours (the feature prior alone is evaluated after it).
    /^RPE frame-to-frame/ && t == "" { t = $5 * 1000; r = $7 }
    /^ATE rmse/ && a == "" { a = $3 * 1000 }
    /^  registration/ { ms = $2 }
    END { printf "| %-58s | %9.2f | %9.3f | %8.2f | %8.1f |\n", label, t, r, a, ms }' <<<"$out"
done < "$configs"
