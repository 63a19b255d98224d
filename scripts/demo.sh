#!/usr/bin/env bash
# The package's main job on the bundled real sample: odometry over the TUM fr1_xyz excerpt
# (37 frames), trajectory written to build/demo_trajectory.txt, errors against ground truth.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cvo_configure
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" --target cvo_run_sequence cvo_evaluate
data="$CVO_ROOT/test/data/tum_fr1_xyz"
runner=$(find "$CVO_BUILD" -type f -name cvo_run_sequence -perm -u+x | head -n 1)
"$runner" --tum "$data" --camera fr1 --preset "$CVO_ROOT/config/tum_rgbd.yaml" \
  --out "$CVO_BUILD/demo_trajectory.txt" --gt "$data/groundtruth.txt" "$@"
