#!/usr/bin/env bash
# cvo_evaluate end to end on the fixture's ground truth: against itself every error is zero; with
# every pose moved +-3 mm (alternating) along world z, ATE is 3 mm and frame-to-frame RPE 6 mm.
set -euo pipefail
evaluate=$1
gt=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL: $*"; exit 1; }
field() { grep "^$1" "$2" | sed -E "s/^$1[^:]*: ([0-9.]+) m.*/\1/"; }

"$evaluate" --gt "$gt" --est "$gt" | tee "$work/self.txt"
[ "$(field 'ATE rmse' "$work/self.txt")" = "0.000000" ] || fail "ATE of gt against itself"
[ "$(field 'RPE frame-to-frame' "$work/self.txt")" = "0.000000" ] || fail "RPE of gt against itself"
grep -q "0.000000 deg; 0.000000 m/s, 0.000000 deg/s" "$work/self.txt" || fail "rotation RPE not 0"

awk '/^#/ {print; next} {k++; $4 = sprintf("%.6f", $4 + (k % 2 ? 0.003 : -0.003)); print}' \
  "$gt" > "$work/perturbed.txt"
"$evaluate" --gt "$gt" --est "$work/perturbed.txt" | tee "$work/perturbed_report.txt"
ate=$(field 'ATE rmse' "$work/perturbed_report.txt")
rpe=$(field 'RPE frame-to-frame' "$work/perturbed_report.txt")
awk -v a="$ate" 'BEGIN { exit !(a > 0.00295 && a < 0.00305) }' || fail "ATE $ate, expected 0.003"
awk -v r="$rpe" 'BEGIN { exit !(r > 0.005999 && r < 0.006001) }' || fail "RPE $rpe, expected 0.006"

printf '1.0 0 0 0 0 0 0\n' > "$work/bad.txt"
if "$evaluate" --gt "$gt" --est "$work/bad.txt" 2> "$work/err.txt"; then fail "malformed accepted"; fi
grep -q "bad.txt:1: expected 8 (TUM) or 12 (KITTI), got 7 numbers" "$work/err.txt" ||
  fail "unclear error: $(cat "$work/err.txt")"
echo "cvo_evaluate CLI: all checks passed"
