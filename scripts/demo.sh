#!/usr/bin/env bash
# What users run, on the bundled real sample: build, turn the TUM fr1_xyz excerpt (37 frames) into
# a rosbag, play it headless into the cvo_odometry nodelet, write the trajectory
# (build/demo/trajectory.txt) and print its errors against ground truth. Paced by the nodelet
# (play_bag.launch pace:=true), so a slow or loaded machine drops no frame.
# Options: --rviz (watch it; needs a display), --backend auto|cpu|cuda.
set -euo pipefail
source "$(dirname "$0")/env.sh"
rviz=false backend=auto
while [ $# -gt 0 ]; do
  case "$1" in
    --rviz) rviz=true ;;
    --backend) backend=$2; shift ;;
    *) echo "usage: $0 [--rviz] [--backend auto|cpu|cuda]" >&2; exit 2 ;;
  esac
  shift
done
cvo_configure
[ "$rviz" = false ] || "$CVO_ROOT/scripts/install_deps.sh" viz
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" --target cvo_make_bag cvo_odometry_nodelet cvo_evaluate
set +u  # the devel setup reads unset variables
source "$CVO_BUILD/devel/setup.bash"
set -u
export ROS_PACKAGE_PATH="$CVO_ROOT:/usr/share"
bin="$CVO_BUILD/devel/lib/cvo_odometry"
data="$CVO_ROOT/test/data/tum_fr1_xyz"
out="$CVO_BUILD/demo"
mkdir -p "$out"
"$bin/cvo_make_bag" --tum "$data" --out "$out/tum_fr1_xyz.bag"
rm -f "$out/trajectory.txt"
roslaunch cvo_odometry play_bag.launch bag:="$out/tum_fr1_xyz.bag" backend:="$backend" \
  rate:=0.2 pace:=true rviz:="$rviz" trajectory_file:="$out/trajectory.txt" >"$out/roslaunch.log" 2>&1 || true
[ -s "$out/trajectory.txt" ] || { tail -30 "$out/roslaunch.log"; echo "no trajectory written" >&2; exit 1; }
echo "trajectory: $out/trajectory.txt ($(grep -vc '^#' "$out/trajectory.txt") poses; log: $out/roslaunch.log)"
"$bin/cvo_evaluate" --gt "$data/groundtruth.txt" --est "$out/trajectory.txt"
