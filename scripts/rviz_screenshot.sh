#!/usr/bin/env bash
# Makes the README's rviz picture from a bag: plays the bag into the cvo_odometry nodelet with
# rviz (rviz/cvo_odometry.rviz) on a private Xvfb display and ROS master, waits until the bag has
# been played and the odometry has published its last pose, waits until rviz draws a still
# picture, and writes it as a PNG. Needs the build and the test bags (scripts/demo.sh makes both)
# and rviz, xvfb and x11-apps (xwd), x11-utils (xwininfo), ImageMagick (convert):
# `scripts/install_deps.sh viz` installs them.
# Usage: scripts/rviz_screenshot.sh [--bag BAG] [--out PNG] [--kind rgbd|stereo]
#                                   [--backend auto|cpu|cuda] [--timeout SECONDS] [--width PIXELS]
set -euo pipefail
source "$(dirname "$0")/env.sh"
bag="$CVO_ROOT/test/bags/tum_fr1_xyz.bag"
out="$CVO_ROOT/doc/rviz_tum_fr1_xyz.png"
kind=rgbd backend=auto timeout=180 width=1024
usage() {
  echo "usage: $0 [--bag BAG] [--out PNG] [--kind rgbd|stereo] [--backend auto|cpu|cuda]" \
    "[--timeout SECONDS] [--width PIXELS]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || usage
  case "$1" in
    --bag) bag=$2 ;;
    --out) out=$2 ;;
    --kind) kind=$2 ;;
    --backend) backend=$2 ;;
    --timeout) timeout=$2 ;;
    --width) width=$2 ;;
    *) usage ;;
  esac
  shift 2
done
fail() { echo "rviz_screenshot: $*" >&2; exit 1; }
for tool in Xvfb xwd xwininfo rviz convert roslaunch; do
  command -v "$tool" >/dev/null ||
    fail "$tool not found (apt-get install rviz xvfb x11-apps x11-utils imagemagick)"
done
[ -f "$bag" ] || fail "no bag $bag"
bag=$(cd "$(dirname "$bag")" && pwd)/$(basename "$bag")
mkdir -p "$(dirname "$out")"
[ -f "$CVO_BUILD/devel/setup.bash" ] || fail "no build in $CVO_BUILD (run scripts/demo.sh first)"
set +u  # the devel setup reads unset variables
source "$CVO_BUILD/devel/setup.bash"
set -u
export ROS_PACKAGE_PATH="$CVO_ROOT:/usr/share"
ns=$([ "$kind" = stereo ] && echo stereo || echo camera)

work=$(mktemp -d "${TMPDIR:-/tmp}/cvo_rviz_screenshot.XXXXXX")
export ROS_LOG_DIR="$work/log"
xvfb_pid="" launch_pid=""
cleanup() {
  local rc=$?
  trap - EXIT INT TERM
  if [ -n "$launch_pid" ] && kill -0 "$launch_pid" 2>/dev/null; then
    kill -INT "$launch_pid" 2>/dev/null || true  # roslaunch stops its nodes and its master
    for _ in $(seq 100); do kill -0 "$launch_pid" 2>/dev/null || break; sleep 0.1; done
    kill -TERM "$launch_pid" 2>/dev/null || true
    wait "$launch_pid" 2>/dev/null || true
  fi
  if [ -n "$xvfb_pid" ]; then
    kill -TERM "$xvfb_pid" 2>/dev/null || true
    wait "$xvfb_pid" 2>/dev/null || true
  fi
  if [ "$rc" -ne 0 ] && [ -f "$work/roslaunch.log" ]; then
    echo "--- last lines of the roslaunch log:" >&2
    tail -25 "$work/roslaunch.log" >&2
  fi
  rm -rf "$work"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
deadline=$((SECONDS + timeout))
# Runs "$@" every 0.2 s until it succeeds; fails with "$1" (what is awaited) at the deadline or
# when roslaunch has ended.
wait_for() {
  local what=$1
  shift
  until "$@" >/dev/null 2>&1; do
    [ "$SECONDS" -lt "$deadline" ] || fail "timed out after ${timeout} s waiting for $what"
    [ -z "$launch_pid" ] || kill -0 "$launch_pid" 2>/dev/null ||
      fail "roslaunch ended while waiting for $what"
    sleep 0.2
  done
}

# A display of its own: Xvfb picks a free one and writes its number to fd 3.
Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb_pid=$!
wait_for "Xvfb to start" grep -q '[0-9]' "$work/display"
DISPLAY=":$(tr -dc 0-9 <"$work/display")"
export DISPLAY
export LIBGL_ALWAYS_SOFTWARE=1  # OGRE on Mesa's llvmpipe: Xvfb has no GPU

# A master of its own on a free port, so a running ROS system is left alone.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
# stop_at_end:=false: everything (rviz) stays up after the bag, until this script ends it.
roslaunch -p "$port" cvo_odometry play_bag.launch bag:="$bag" kind:="$kind" backend:="$backend" \
  rviz:=true pace:=true stop_at_end:=false >"$work/roslaunch.log" 2>&1 &
launch_pid=$!

wait_for "the rviz window" sh -c "xwininfo -root -tree | grep -q 'RViz'"
# Until the player has come and gone and the odometry has published its last pose.
python3 - "$ns" "$((deadline - SECONDS))" <<'EOF' || fail "the odometry did not finish (see above)"
import sys, time
import rosgraph, rospy
from nav_msgs.msg import Odometry

ns, budget = sys.argv[1], float(sys.argv[2])
end = time.monotonic() + budget
master = rosgraph.Master("/rviz_screenshot_waiter")
while not rosgraph.is_master_online():
    if time.monotonic() > end:
        sys.exit("timed out waiting for the ROS master")
    time.sleep(0.2)
rospy.init_node("rviz_screenshot_waiter", disable_signals=True)
poses = [0, time.monotonic()]
def on_odom(_):
    poses[0] += 1
    poses[1] = time.monotonic()
rospy.Subscriber("/%s/odom" % ns, Odometry, on_odom)

def player_alive():
    try:
        master.lookupNode("/player")
        return True
    except Exception:
        return False

seen_player = False
while True:
    if time.monotonic() > end:
        sys.exit("timed out: player %s, %d poses received" %
                 ("seen" if seen_player else "never seen", poses[0]))
    alive = player_alive()
    seen_player = seen_player or alive
    if seen_player and not alive and poses[0] > 0 and time.monotonic() - poses[1] > 1.5:
        break
    time.sleep(0.2)
print("rviz_screenshot: the bag is played, %d poses received" % poses[0])
EOF

# rviz keeps drawing at its frame rate: capture until two pictures in a row are the same.
capture() { xwd -root -silent -display "$DISPLAY" >"$work/$1.xwd"; }
capture shot.prev
stable() {
  capture shot
  if cmp -s "$work/shot.xwd" "$work/shot.prev.xwd"; then return 0; fi
  mv "$work/shot.xwd" "$work/shot.prev.xwd"
  return 1
}
wait_for "a still rviz picture" stable
# 256 colours: a third of the size, no visible loss on this kind of picture.
convert "xwd:$work/shot.xwd" -resize "${width}x>" -strip -colors 256 "png8:$out"
echo "rviz_screenshot: wrote $out ($(du -k "$out" | cut -f1) KB) in ${SECONDS} s"
