#!/usr/bin/env bash
# Installs the Debian 12 packages cvo_odometry needs; quick and quiet when they are all present.
# Usage: scripts/install_deps.sh [core|full|tools|peers|viz|sanitize]
#   core: CMake, compiler, Eigen, GoogleTest, Thrust (device_cpu); full: + OpenCV and ROS; tools:
#   full + the ROS command-line tools (rostopic, rosservice, rosnode, rosparam, rosmsg, roswtf,
#   tf_echo, tf2's echo.py and view_frames; dynparam is in full), catkin build and catkin_lint;
#   peers: + PCL, Open3D, OpenCV contrib; viz: tools + rviz; sanitize: core + OpenCV + clang and
#   its runtimes
set -euo pipefail
profile=${1:-full}

# libthrust-dev (with libcub-dev): the device code on CPU threads (device_cpu) without CUDA.
core=(cmake g++ make libeigen3-dev libgtest-dev libthrust-dev libcub-dev)
full=("${core[@]}" libopencv-dev clang-format
  catkin ros-message-generation ros-message-runtime ros-std-msgs libroscpp-dev libstd-msgs-dev
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libnodeletlib-dev libnodelet-dev
  libnodeletlib-tools libmessage-filters-dev libtf2-ros-dev libdynamic-reconfigure-config-init-mutex-dev
  python3-dynamic-reconfigure librostest-dev python3-rostest python3-roslaunch rosout rosbash
  rospack-tools librosbag-dev python3-rosbag python3-sensor-msgs python3-nav-msgs python3-tf2-msgs
  ros-std-msgs ros-sensor-msgs ros-nav-msgs ros-geometry-msgs ros-stereo-msgs libstereo-msgs-dev
  libcv-bridge-dev libimage-transport-dev libdiagnostic-updater-dev libdiagnostic-msgs-dev
  ros-diagnostic-msgs libstereo-image-proc-dev ros-stereo-image-proc python3-matplotlib
  libstd-srvs-dev ros-std-srvs libtf2-geometry-msgs-dev)
# The command-line tools a ROS user reaches for while the node runs: rostopic, rosservice, rosnode,
# rosparam, rosmsg, roswtf (python3-ros*; std_srvs' Python types for rosservice call on the reset
# and trigger services), `rosrun tf tf_echo` (tf-tools, with libtf-dev for the package's
# manifest), `rosrun tf2_tools echo.py|view_frames.py` (tf2-tools); `rosrun dynamic_reconfigure
# dynparam` comes with python3-dynamic-reconfigure in full. catkin-tools (`catkin build`) and
# catkin-lint (CI's check of the package's CMake files).
tools=("${full[@]}" python3-rostopic python3-rosservice python3-rosnode python3-rosparam
  python3-rosmsg python3-roswtf python3-std-srvs libtf-dev tf-tools tf2-tools catkin-tools
  catkin-lint)
# rviz only for watching (scripts/demo.sh --rviz) and the README picture (scripts/rviz_screenshot.sh:
# Xvfb, xwd, xwininfo, ImageMagick): large, not needed by the tests.
viz=("${tools[@]}" rviz xvfb x11-apps x11-utils imagemagick)
# The checking build (scripts/test_sanitizers.sh): clang with its sanitizer and libFuzzer runtimes
# and its OpenMP (libomp: the CPU backend's threads and device_cpu).
sanitize=("${core[@]}" libopencv-dev clang libclang-rt-14-dev libomp-14-dev)
# Peers for bench/peer_table.sh only (large: PCL, Open3D, OpenCV contrib).
peers=(libopencv-contrib-dev libpcl-dev python3-open3d python3-numpy)

case "$profile" in
  core) wanted=("${core[@]}") ;;
  full) wanted=("${full[@]}") ;;
  tools) wanted=("${tools[@]}") ;;
  peers) wanted=("${full[@]}" "${peers[@]}") ;;
  viz) wanted=("${viz[@]}") ;;
  sanitize) wanted=("${sanitize[@]}") ;;
  *) echo "usage: $0 [core|full|tools|peers|viz|sanitize]" >&2; exit 2 ;;
esac

missing=()
for pkg in "${wanted[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
