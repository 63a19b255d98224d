#!/usr/bin/env bash
# Checks cvo_odometry's install space as a ROS user gets it from `catkin_make install`: the
# libraries, headers, launch files, presets, rviz view, plugin description and tools are there;
# with only the install space's setup.bash sourced (the source tree and the build folder hidden
# where this runs as root), the tools answer --help, cvo_run_sequence runs the bundled TUM
# excerpt with the preset by name and by installed file, cvo_make_bag writes a bag, the nodelet
# loads from the install space and turns that bag into a trajectory of every frame
# (play_bag.launch), and a program compiles and links against the installed headers and libraries.
#
# Usage: scripts/check_install.sh BUILD_DIR
#          installs BUILD_DIR (a build of this package, or a catkin_make workspace's build/) into
#          a temporary folder (cmake --install with DESTDIR; the build's prefix is untouched)
#          after building its `all` (as `make install` does), and checks that
#        scripts/check_install.sh --prefix PREFIX [--source DIR] [--hide DIR]...
#          checks an install space already there (e.g. a workspace's install/ after
#          `catkin_make install`) of the package in DIR (default: this checkout), hiding the
#          DIRs (e.g. the workspace's src/, build/ and devel/) too
# Options: --keep (keep the temporary folder, which a failure keeps anyway for its logs),
#          --no-replay (skip the bag replay: ~20 s)
# Prints a line per check; exits non-zero at the first failure with one line saying what failed.
set -euo pipefail
source "$(dirname "$0")/env.sh"

usage() {
  echo "usage: $0 BUILD_DIR | --prefix PREFIX [--source DIR] [--hide DIR]...  [--keep] [--no-replay]" >&2
  exit 2
}
build="" prefix="" source_dir="" keep=false replay=true hide=()
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) [ $# -ge 2 ] || usage; prefix=$2; shift ;;
    --hide) [ $# -ge 2 ] || usage; hide+=("$2"); shift ;;
    --source) [ $# -ge 2 ] || usage; source_dir=$2; shift ;;
    --keep) keep=true ;;
    --no-replay) replay=false ;;
    -h|--help) usage ;;
    -*) echo "unknown option $1" >&2; usage ;;
    *) [ -z "$build" ] || usage; build=$1 ;;
  esac
  shift
done
[ -n "$build" ] || [ -n "$prefix" ] || usage
[ -z "$build" ] || [ -z "$prefix" ] || usage

fail() { echo "install check FAILED: $*" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/cvo_install_check.XXXXXX")

if [ -n "$build" ]; then
  [ -f "$build/CMakeCache.txt" ] || fail "$build is not a configured build folder (no CMakeCache.txt)"
  build=$(cd "$build" && pwd)
  configured_prefix=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$build/CMakeCache.txt")
  [ -n "$configured_prefix" ] || fail "no CMAKE_INSTALL_PREFIX in $build/CMakeCache.txt"
  cmake --build "$build" -j"$(cvo_jobs)" >"$work/build.log" 2>&1 ||
    fail "building $build's all failed (log: $work/build.log): $(grep -m1 -iE 'error' "$work/build.log")"
  DESTDIR="$work/destdir" cmake --install "$build" >"$work/install.log" 2>&1 ||
    fail "cmake --install $build failed: $(grep -m1 -iE 'error' "$work/install.log")"
  prefix="$work/destdir$configured_prefix"
  hide+=("$build")
  # The package's sources that build was configured from (a workspace's copy, a clone).
  [ -n "$source_dir" ] || source_dir=$(sed -n 's/^cvo_odometry_SOURCE_DIR:STATIC=//p' "$build/CMakeCache.txt")
  echo "installed $build into $prefix (its prefix: $configured_prefix)"
fi
[ -f "$prefix/setup.bash" ] || fail "no setup.bash in $prefix: not a catkin install space"
source_dir=${source_dir:-$CVO_ROOT}
[ -f "$source_dir/package.xml" ] || fail "$source_dir holds no package (--source)"
source_dir=$(cd "$source_dir" && pwd)
prefix=$(cd "$prefix" && pwd)
share="$prefix/share/cvo_odometry"
bin="$prefix/lib/cvo_odometry"

# --- What must be there ------------------------------------------------------------------------
missing=()
need() { [ -e "$1" ] || missing+=("${1#"$prefix"/}"); }
for lib in cvo_core cvo_frontend cvo_odometry_ros cvo_odometry_nodelet; do
  need "$prefix/lib/lib$lib.so"
done
(cd "$source_dir/include" && find cvo_odometry -type f) >"$work/headers"
while read -r header; do need "$prefix/include/$header"; done <"$work/headers"
for generated in CvoIndicator.h ResetToPose.h CvoOdometryConfig.h; do
  need "$prefix/include/cvo_odometry/$generated"
done
need "$share/package.xml"
need "$share/nodelet_plugins.xml"
for dir in launch config rviz; do
  for f in "$source_dir/$dir"/*; do need "$share/$dir/$(basename "$f")"; done
done
tools=(cvo_run_sequence cvo_evaluate cvo_make_bag cvo_align cvo_soak cvo_make_labels
       cvo_settings_table cvo_benchmark cvo_wait_idle)
for tool in "${tools[@]}"; do need "$bin/$tool"; done
[ ${#missing[@]} -eq 0 ] ||
  fail "${#missing[@]} files missing from $prefix: ${missing[*]:0:8}$([ ${#missing[@]} -le 8 ] || echo " ...")"
echo "layout: libraries, $(wc -l <"$work/headers") headers + 3 generated, launch, config, rviz," \
  "nodelet_plugins.xml and ${#tools[@]} tools present"

# No installed file names a data path in the source tree or the build folder (compiled-in
# preset or fixture paths would only work on the machine that built them). Source file names in
# log macros (__FILE__) and Python's byte code are no data paths.
leaks=()
for dir in "$source_dir" "$CVO_ROOT" "${hide[@]}"; do
  for sub in config launch rviz test cfg msg devel/share devel/lib; do
    while IFS= read -r f; do leaks+=("${f#"$prefix"/}: $dir/$sub"); done < <(
      grep -rlF --exclude='*.pyc' "$dir/$sub/" "$prefix" 2>/dev/null || true)
  done
done
[ ${#leaks[@]} -eq 0 ] || fail "installed files name paths outside the install space: ${leaks[*]}"
echo "paths: no installed file names the source tree's or the build's data folders"

# --- Run it from the install space alone -------------------------------------------------------
# The fixture is copied out: the checks below must not see the source tree.
data="$work/tum_fr1_xyz"
cp -r "$source_dir/test/data/tum_fr1_xyz" "$data"
port=$(cvo_free_port)
{ echo "set -euo pipefail"; declare -f cvo_bag_frames cvo_pose_count cvo_first_error cvo_roslaunch_logged; } >"$work/inner.sh"
cat >>"$work/inner.sh" <<EOF
fail() { echo "install check FAILED: \$*" >&2; exit 1; }
for dir in "\$@"; do  # the folders hidden from this run
  [ -z "\$(ls -A "\$dir")" ] || fail "\$dir is still visible"
done
cd "$work"
set +u; source "$prefix/setup.bash"; set -u
export ROS_MASTER_URI=http://localhost:$port ROS_HOSTNAME=localhost ROS_HOME="$work/ros_home"
[ "\$(rospack find cvo_odometry)" = "$share" ] ||
  fail "rospack find cvo_odometry: \$(rospack find cvo_odometry 2>&1) (want $share)"
rospack plugins --attrib=plugin nodelet | grep -qF "$share/nodelet_plugins.xml" ||
  fail "nodelet's plugin list lacks $share/nodelet_plugins.xml"
python3 -c 'from cvo_odometry.msg import CvoIndicator; from cvo_odometry.srv import ResetToPose
from cvo_odometry.cfg import CvoOdometryConfig' 2>"$work/python.log" ||
  fail "Python messages: \$(tail -1 "$work/python.log")"
echo "environment: rospack finds the package and its nodelet plugin in the install space; the Python messages, service and config import"

# ldd: every library a program or the nodelet needs resolves, none in a hidden folder.
for f in "$prefix"/lib/*.so "$bin"/*; do
  file -b "\$f" | grep -q ELF || continue
  if ldd "\$f" | grep -q 'not found'; then
    fail "\${f#$prefix/}: \$(ldd "\$f" | grep 'not found' | tr -s ' \t' ' ' | paste -sd,)"
  fi
done
# Every installed program answers --help (cvo_settings_table prints the table without options).
for f in "$bin"/*; do
  [ -x "\$f" ] || continue
  name=\$(basename "\$f")
  if [ "\$name" = cvo_settings_table ]; then args=(); else args=(--help); fi
  "\$f" "\${args[@]}" >"$work/help.log" 2>&1 || fail "\$name \${args[*]} exited \$?: \$(tail -1 "$work/help.log")"
  [ -s "$work/help.log" ] || fail "\$name \${args[*]} printed nothing"
done
echo "tools: \$(ls "$bin" | wc -l) programs answer --help; every library resolves"

frames=\$(awk '!/^#/ && NF' "$data/associations.txt" | head -10 | wc -l)
for preset in tum_rgbd "$share/config/tum_rgbd.yaml"; do
  "$bin/cvo_run_sequence" --tum "$data" --last 9 --preset "\$preset" --backend cpu --quiet \
    --out "$work/run.txt" >"$work/run.log" 2>&1 || fail "cvo_run_sequence --preset \$preset: \$(tail -1 "$work/run.log")"
  [ "\$(cvo_pose_count "$work/run.txt")" -eq "\$frames" ] ||
    fail "cvo_run_sequence --preset \$preset wrote \$(cvo_pose_count "$work/run.txt") of \$frames poses"
done
"$bin/cvo_evaluate" --gt "$data/groundtruth.txt" --est "$work/run.txt" >"$work/evaluate.log" 2>&1 ||
  fail "cvo_evaluate: \$(tail -1 "$work/evaluate.log")"
echo "cvo_run_sequence: \$frames of \$frames poses with the preset by name and by installed file; cvo_evaluate reads them"

# A downstream program: the installed headers (core, front end, generated messages) and
# libraries through catkin's CMake config, as a package that depends on cvo_odometry gets them.
mkdir -p "$work/downstream"
cat >"$work/downstream/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.18)
project(cvo_downstream CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(catkin REQUIRED COMPONENTS cvo_odometry)
add_executable(downstream main.cpp)
target_include_directories(downstream SYSTEM PRIVATE \${catkin_INCLUDE_DIRS})
target_link_libraries(downstream \${catkin_LIBRARIES})
CMAKE
cat >"$work/downstream/main.cpp" <<'CPP'
#include <cvo_odometry/CvoIndicator.h>
#include <cvo_odometry/core/lie_group.hpp>
#include <cvo_odometry/frontend/builtin_presets.hpp>
#include <iostream>
int main() {
  cvo_odometry::CvoIndicator indicator;
  cvo::OdometrySettings settings;
  cvo::applyPreset("tum_rgbd", &settings);
  const Eigen::Matrix3d rotation = cvo::lie::expSO3(Eigen::Vector3d(0.1, 0.0, 0.0));
  std::cout << cvo::builtInPresets().size() << " built-in presets, det R " << rotation.determinant();
  return static_cast<int>(indicator.header.seq);
}
CPP
(cmake -S "$work/downstream" -B "$work/downstream/build" -DCMAKE_BUILD_TYPE=Release &&
 cmake --build "$work/downstream/build") >"$work/downstream.log" 2>&1 ||
  fail "a downstream package does not build against the install space (log: $work/downstream.log): \$(grep -m1 -E 'error|Error' "$work/downstream.log")"
"$work/downstream/build/downstream" >"$work/downstream_run.log" 2>&1 ||
  fail "the downstream program does not run: \$(tail -1 "$work/downstream_run.log")"
echo "downstream: find_package(catkin COMPONENTS cvo_odometry) builds, links and runs a program (\$(cat "$work/downstream_run.log"))"

if [ "$replay" = true ]; then
  "$bin/cvo_make_bag" --tum "$data" --stride 3 --out "$work/tum.bag" >"$work/make_bag.log" 2>&1 ||
    fail "cvo_make_bag: \$(tail -1 "$work/make_bag.log")"
  bag_frames=\$(cvo_bag_frames "$work/tum.bag") || fail "cannot read the bag of cvo_make_bag"
  cvo_roslaunch_logged "$work/roslaunch.log" cvo_odometry play_bag.launch bag:="$work/tum.bag" \
    rate:=0.2 pace:=true trajectory_file:="$work/replay.txt" || true
  replayed=0
  [ ! -f "$work/replay.txt" ] || replayed=\$(cvo_pose_count "$work/replay.txt")
  [ "\$replayed" -eq "\$bag_frames" ] ||
    fail "play_bag.launch from the install space: \$replayed of \$bag_frames poses; first error: \$(cvo_first_error "$work/roslaunch.log") (log: $work/roslaunch.log)"
  echo "nodelet: loaded from the install space, \$bag_frames of \$bag_frames poses from a bag of cvo_make_bag (play_bag.launch)"
fi
EOF

# Hide the source tree and the build (root: a private mount namespace, as
# scripts/check_core_isolation.sh does); otherwise the environment alone keeps them out.
clean_env=(env -i HOME="$HOME" PATH=/usr/bin:/bin TMPDIR="${TMPDIR:-/tmp}" LANG=C.UTF-8)
if [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null; then
  mkdir -p "$work/empty"
  candidates=()
  for dir in "$source_dir" "$CVO_ROOT" "${hide[@]}"; do
    [ -d "$dir" ] && candidates+=("$(cd "$dir" && pwd)")
  done
  # Each folder once, none inside another (a mount over the outer one hides it).
  mounts="" hidden=()
  for dir in "${candidates[@]}"; do
    inside=false
    for other in "${candidates[@]}" "${hidden[@]}"; do
      [ "$other" != "$dir" ] || continue
      case "$dir/" in "$other"/*) inside=true ;; esac
    done
    for h in "${hidden[@]}"; do [ "$h" != "$dir" ] || inside=true; done
    [ "$inside" = true ] || { hidden+=("$dir"); mounts+="mount --bind '$work/empty' '$dir' && "; }
  done
  echo "hiding the source tree and build: ${hidden[*]}"
  "${clean_env[@]}" unshare -m bash -c "$mounts exec bash '$work/inner.sh' ${hidden[*]}"
else
  echo "not root: the source tree and build stay visible; only the environment is clean"
  "${clean_env[@]}" bash "$work/inner.sh"
fi
echo "install check passed: $prefix"
[ "$keep" = true ] || rm -rf "$work"
