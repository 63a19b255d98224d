#!/usr/bin/env bash
# What users run, on the bundled real sample: build, turn the TUM fr1_xyz excerpt (37 frames) into
# a rosbag, play it headless into the cvo_odometry nodelet, write the trajectory
# (build/demo/trajectory.txt) and print its errors against ground truth. Paced by the nodelet
# (play_bag.launch pace:=true), so a slow or loaded machine drops no frame. The trajectory must
# hold a pose for every frame of the bag; otherwise the demo says in one line what failed and
# exits non-zero.
# Options: --rviz (watch it; needs a display), --backend auto|cpu|cuda.
set -euo pipefail
source "$(dirname "$0")/env.sh"
rviz=false backend=auto
while [ $# -gt 0 ]; do
  case "$1" in
    --rviz) rviz=true ;;
    --backend)
      [ $# -ge 2 ] || { echo "usage: $0 [--rviz] [--backend auto|cpu|cuda]" >&2; exit 2; }
      backend=$2; shift ;;
    *) echo "usage: $0 [--rviz] [--backend auto|cpu|cuda]" >&2; exit 2 ;;
  esac
  shift
done
fail() { echo "demo FAILED: $*" >&2; exit 1; }
cvo_configure || fail "configuring $CVO_BUILD failed (log: $CVO_BUILD/configure.log)"
[ "$rviz" = false ] || "$CVO_ROOT/scripts/install_deps.sh" viz
# The package without its tests (`all`): the nodelet, cvo_make_bag, cvo_evaluate and the
# generated Python messages that play_bag.launch's cvo_wait_idle imports.
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" || fail "the build failed (the compiler's errors are above)"
set +u  # the devel setup reads unset variables
source "$CVO_BUILD/devel/setup.bash"
set -u
export ROS_PACKAGE_PATH="$CVO_ROOT:/usr/share"
bin="$CVO_BUILD/devel/lib/cvo_odometry"
data="$CVO_ROOT/test/data/tum_fr1_xyz"
out="$CVO_BUILD/demo"
mkdir -p "$out"
"$bin/cvo_make_bag" --tum "$data" --out "$out/tum_fr1_xyz.bag" || fail "cvo_make_bag failed"
frames=$(cvo_bag_frames "$out/tum_fr1_xyz.bag") || fail "cannot read $out/tum_fr1_xyz.bag"
rm -f "$out/trajectory.txt"
launch_rc=0
cvo_roslaunch_logged "$out/roslaunch.log" cvo_odometry play_bag.launch bag:="$out/tum_fr1_xyz.bag" \
  backend:="$backend" rate:=0.2 pace:=true rviz:="$rviz" trajectory_file:="$out/trajectory.txt" ||
  launch_rc=$?
poses=0
[ ! -f "$out/trajectory.txt" ] || poses=$(cvo_pose_count "$out/trajectory.txt")
if [ "$poses" -ne "$frames" ]; then
  why=$(cvo_first_error "$out/roslaunch.log")
  hung=""
  if [ "$launch_rc" -eq 124 ]; then
    player=$(tail -qn1 "$ROS_HOME"/log/latest/player-*-stdout.log 2>/dev/null | tr -d '\r' || true)
    hung="; the replay hung, stopped after ${CVO_ROSLAUNCH_LIMIT:-900} s (the bag player's last"
    hung+=" line: '${player:-none}')"
  fi
  fail "$poses of $frames poses in $out/trajectory.txt$hung${why:+; first error: $why}" \
    "(log: $out/roslaunch.log)"
fi
echo "trajectory: $out/trajectory.txt ($poses of $frames poses; log: $out/roslaunch.log)"
"$bin/cvo_evaluate" --gt "$data/groundtruth.txt" --est "$out/trajectory.txt" ||
  fail "cvo_evaluate could not evaluate $out/trajectory.txt"
