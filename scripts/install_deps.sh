#!/usr/bin/env bash
# Installs the Debian 12 packages cvo_odometry needs; quick and quiet when they are all present.
# Usage: scripts/install_deps.sh [core|full]   (core: CMake, compiler, Eigen, GoogleTest only)
set -euo pipefail
profile=${1:-full}

core=(cmake g++ make libeigen3-dev libgtest-dev)
full=("${core[@]}" libopencv-dev clang-format
  catkin ros-message-generation ros-message-runtime ros-std-msgs libroscpp-dev libstd-msgs-dev
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libnodeletlib-dev libnodelet-dev
  libnodeletlib-tools libmessage-filters-dev libtf2-ros-dev libdynamic-reconfigure-config-init-mutex-dev
  python3-dynamic-reconfigure librostest-dev python3-rostest python3-roslaunch rosout rosbash
  rospack-tools librosbag-dev python3-rosbag python3-sensor-msgs python3-nav-msgs python3-tf2-msgs)

case "$profile" in
  core) wanted=("${core[@]}") ;;
  full) wanted=("${full[@]}") ;;
  *) echo "usage: $0 [core|full]" >&2; exit 2 ;;
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
