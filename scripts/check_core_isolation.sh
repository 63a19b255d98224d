#!/usr/bin/env bash
# Proves the ROS-free build needs only CMake, a compiler and Eigen (and CUDA if present): it
# configures, builds and tests the core in a private mount namespace where ROS (catkin, its
# headers and CMake configs) and OpenCV are hidden behind empty folders. Needs root (unshare).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-/tmp/cvo_core_isolated}"
hide=(/usr/bin/catkin_make /usr/share/catkin /usr/include/ros /usr/include/opencv4
      /usr/lib/x86_64-linux-gnu/cmake/opencv4 /usr/share/catkin_pkg /usr/include/nodelet
      /usr/lib/python3/dist-packages/catkin /usr/share/OpenCV)
unshare -m bash -euo pipefail -c "
  empty=\$(mktemp -d); empty_file=\$(mktemp)
  for p in ${hide[*]}; do
    if [ -d \"\$p\" ]; then mount --bind \"\$empty\" \"\$p\"; elif [ -e \"\$p\" ]; then mount --bind \"\$empty_file\" \"\$p\"; fi
  done
  test ! -e /usr/include/opencv4/opencv2/core.hpp && test ! -e /usr/include/ros/ros.h
  echo 'ROS and OpenCV hidden'
  rm -rf '$build'
  cmake -S '$root' -B '$build' -DCVO_WITH_ROS=OFF | grep 'cvo_odometry:'
  cmake --build '$build' -j\$(nproc) >/dev/null
  cd '$build' && ctest --output-on-failure -j\$(nproc) | grep -E 'tests passed|tests failed|Skipped'
"
