#!/usr/bin/env bash
# A ROS user's catkin workspace, from the manual's commands: the package copied into WS/src,
# built with the workspace's defaults (no test programs; CUDA code for this machine's GPUs),
# `source devel/setup.bash` and `roslaunch cvo_odometry rgbd.launch` until the nodelet's services
# are up, then the install space (`catkin_make install`, or catkin-tools' install
# space) checked by scripts/check_install.sh with the workspace's source, build and devel
# folders hidden. Prints each step and its time; exits non-zero with one line at the first failure.
#
# Usage: scripts/check_workspace.sh [--tool catkin_make|catkin] [--ws DIR] [--keep]
#                                   [--run-tests] [-- CMAKE_ARGS...]
#   --tool     catkin_make (default) or catkin (catkin-tools: catkin build)
#   --ws DIR   the workspace (default: a new temporary folder, removed after a pass unless --keep,
#              kept after a failure for its logs);
#              an existing DIR/src/cvo_odometry is replaced by a copy of this checkout
#   --run-tests  also `catkin_make run_tests` and catkin_test_results (builds every test: long)
#   CMAKE_ARGS e.g. -DCVO_WITH_CUDA=OFF, -DCMAKE_CUDA_ARCHITECTURES=86
set -euo pipefail
source "$(dirname "$0")/env.sh"

usage() {
  echo "usage: $0 [--tool catkin_make|catkin] [--ws DIR] [--keep] [--run-tests] [-- CMAKE_ARGS...]" >&2
  exit 2
}
tool=catkin_make ws="" keep=false run_tests=false cmake_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --tool) [ $# -ge 2 ] || usage; tool=$2; shift ;;
    --ws) [ $# -ge 2 ] || usage; ws=$2; shift ;;
    --keep) keep=true ;;
    --run-tests) run_tests=true ;;
    --) shift; cmake_args=("$@"); break ;;
    *) usage ;;
  esac
  shift
done
case "$tool" in catkin_make|catkin) ;; *) usage ;; esac

fail() { echo "workspace check FAILED: $* (workspace: ${ws:-none})" >&2; exit 1; }
step_start=$SECONDS
step() { echo "workspace: $* ($((SECONDS - step_start)) s)"; step_start=$SECONDS; }

"$CVO_ROOT/scripts/install_deps.sh" full
[ "$tool" = catkin_make ] || "$CVO_ROOT/scripts/install_deps.sh" tools
temporary=false
if [ -z "$ws" ]; then
  ws=$(mktemp -d "${TMPDIR:-/tmp}/cvo_ws.XXXXXX")
  temporary=true
fi
mkdir -p "$ws/src"
ws=$(cd "$ws" && pwd)
log="$ws/check_logs"
mkdir -p "$log"

# The package's files as git sees them (tracked and new, not ignored: no build folders).
pkg="$ws/src/cvo_odometry"
rm -rf "$pkg"
mkdir -p "$pkg"
(cd "$CVO_ROOT" && git ls-files -z --cached --others --exclude-standard |
   while IFS= read -r -d '' f; do [ -e "$f" ] && printf '%s\0' "$f"; done |
   tar --null -T - -cf -) | tar -xf - -C "$pkg"
step "copied $CVO_ROOT into $pkg"

cd "$ws"
if [ "$tool" = catkin_make ]; then
  catkin_make -j"$(cvo_jobs)" "${cmake_args[@]}" >"$log/build.log" 2>&1 ||
    fail "catkin_make failed (log: $log/build.log): $(grep -m1 -E 'error|Error' "$log/build.log")"
else
  catkin init >/dev/null
  catkin config --install --cmake-args "${cmake_args[@]}" >/dev/null
  catkin build --no-status -j"$(cvo_jobs)" >"$log/build.log" 2>&1 ||
    fail "catkin build failed (log: $log/build.log): $(grep -m1 -E 'error|Error' "$log/build.log")"
fi
grep -h "cvo_odometry:" "$log/build.log" | sed 's/^ *-- */  /' || true
step "$tool built the workspace"

# The devel space: roslaunch cvo_odometry rgbd.launch, until the nodelet's services are up (or a
# node dies or logs FATAL, or CVO_ROSLAUNCH_LIMIT s pass: a hang).
port=$(cvo_free_port)
devel_check=$(cat <<EOF
set -euo pipefail
set +u; source "$ws/devel/setup.bash"; set -u
export ROS_MASTER_URI=http://localhost:$port
: >"$log/rgbd_launch.log"
roslaunch cvo_odometry rgbd.launch >>"$log/rgbd_launch.log" 2>&1 &
launch=\$!
loaded=false
while kill -0 \$launch 2>/dev/null; do
  # The nodelet's own services are there once it is loaded and initialized.
  if python3 -c 'import rosgraph; print(*(s for s, _ in rosgraph.Master("/check").getSystemState()[2]))' \
       2>/dev/null | grep -qw /camera/cvo_odometry/reset; then
    loaded=true
    break
  fi
  grep -qE 'has died|\[FATAL\]' "$log/rgbd_launch.log" && break
  # A bound only a hang reaches (as in scripts/env.sh's cvo_roslaunch_logged).
  [ \$SECONDS -lt ${CVO_ROSLAUNCH_LIMIT:-900} ] || { echo "not up after \$SECONDS s: stopped" >>"$log/rgbd_launch.log"; break; }
  sleep 1
done
kill -INT \$launch 2>/dev/null || true
wait \$launch || true
[ \$loaded = true ]
EOF
)
env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 ROS_HOSTNAME=localhost ROS_HOME="$ws/ros_home" \
  bash -c "$devel_check" ||
  fail "devel space: roslaunch cvo_odometry rgbd.launch did not bring the nodelet up; first error:" \
    "$(cvo_first_error "$log/rgbd_launch.log") (log: $log/rgbd_launch.log)"
step "devel space: roslaunch cvo_odometry rgbd.launch loaded the nodelet"

if [ "$tool" = catkin_make ]; then
  catkin_make install -j"$(cvo_jobs)" "${cmake_args[@]}" >"$log/install.log" 2>&1 ||
    fail "catkin_make install failed (log: $log/install.log): $(grep -m1 -E 'error|Error' "$log/install.log")"
  step "catkin_make install"
fi
if ! "$CVO_ROOT/scripts/check_install.sh" --prefix "$ws/install" --source "$pkg" --hide "$ws/src" \
       --hide "$ws/build" --hide "$ws/devel" 2>&1 | sed 's/^/  /'; then
  fail "the install space $ws/install failed its check (above)"
fi
step "install space checked"

if [ "$run_tests" = true ]; then
  [ "$tool" = catkin_make ] || fail "--run-tests is for catkin_make"
  catkin_make run_tests -j"$(cvo_jobs)" "${cmake_args[@]}" >"$log/run_tests.log" 2>&1 ||
    fail "catkin_make run_tests failed (log: $log/run_tests.log): $(grep -m1 -E 'Failed|error' "$log/run_tests.log")"
  (set +u; source "$ws/devel/setup.bash"; catkin_test_results "$ws/build/test_results") ||
    fail "catkin_test_results: a test failed (log: $log/run_tests.log)"
  step "catkin_make run_tests: every test passed"
fi
echo "workspace check passed: $ws"
if [ "$temporary" = true ] && [ "$keep" = false ]; then
  cd /
  rm -rf "$ws"
fi
