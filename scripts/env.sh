# Sourced by the scripts: Debian's python3 and ROS tools first (pyenv's python3 cannot import
# catkin_pkg or rospy), CUDA's nvcc visible, ROS traffic on loopback.
export PATH="/usr/bin:/bin:/usr/local/cuda/bin:${PATH}"
export PYENV_VERSION=system
export ROS_HOSTNAME=localhost
export ROS_HOME="${ROS_HOME:-${TMPDIR:-/tmp}/cvo_odometry_ros_home}"
mkdir -p "$ROS_HOME"
CVO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CVO_BUILD="${CVO_BUILD:-$CVO_ROOT/build}"
cvo_jobs() { nproc 2>/dev/null || echo 2; }

# The CUDA architectures CI builds: all that the users have (Turing, Ampere desktop, Jetson Orin,
# Ada, Hopper H100/H200 also as PTX for newer chips, Blackwell desktop). CVO_CUDA_ARCHITECTURES=all
# selects them; a list (e.g. "86;90") those; unset: CMake's choice (cmake/CvoCuda.cmake: the GPUs
# nvidia-smi lists, else 75), or what the build folder has cached.
CVO_CUDA_ARCHITECTURES_ALL="75-real;86-real;87-real;89-real;90;120-real"

# Installs what is missing and configures the ROS build in $CVO_BUILD (log: configure.log).
cvo_configure() {
  "$CVO_ROOT/scripts/install_deps.sh" full
  mkdir -p "$CVO_BUILD"
  local args=(-DCMAKE_BUILD_TYPE=Release -DCVO_WITH_DEVICE_CPU=ON)
  case "${CVO_CUDA_ARCHITECTURES:-}" in
    "") ;;
    all) args+=(-DCMAKE_CUDA_ARCHITECTURES="$CVO_CUDA_ARCHITECTURES_ALL") ;;
    *) args+=(-DCMAKE_CUDA_ARCHITECTURES="$CVO_CUDA_ARCHITECTURES") ;;
  esac
  # device_cpu ON: the device code's tests must run, never be skipped for want of Thrust.
  cmake -S "$CVO_ROOT" -B "$CVO_BUILD" "${args[@]}" >"$CVO_BUILD/configure.log" 2>&1 ||
    { cat "$CVO_BUILD/configure.log"; return 1; }
  grep "cvo_odometry:" "$CVO_BUILD/configure.log" || true
}

# Counts the device-code parity tests (test_cuda_parity) in a ctest log, per device, into the
# log of the run; fails when none passed on device_cpu: the device code must run in every CI run.
cvo_parity_summary() {
  local log=$1
  _cvo_count() { grep -cE "Test +#[0-9]+: [^ ]*$1[^ ]* .*[ .]$2" "$log" || true; }
  local passed failed gpu_passed gpu_skipped
  passed=$(_cvo_count '(device_cpu|DeviceCpu\.)' 'Passed')
  failed=$(_cvo_count '(device_cpu|DeviceCpu\.)' '\*\*\*Failed')
  gpu_passed=$(_cvo_count '/cuda' 'Passed')
  gpu_skipped=$(_cvo_count '/cuda' '\*\*\*Skipped')
  echo "device code parity tests: device_cpu (CPU threads) $passed passed, $failed failed;" \
    "cuda (GPU) $gpu_passed passed, $gpu_skipped skipped"
  [ "$passed" -gt 0 ] || { echo "no device_cpu parity test ran" >&2; return 1; }
}

# A free TCP port (for a ROS master of our own: ROS_MASTER_URI=http://localhost:PORT, so that a
# run does not join or clash with another master on this machine).
cvo_free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])'
}

# Frames in a bag of cvo_make_bag: the fewest messages of its image topics (colour and depth, or
# left and right), the frames the odometry can pair.
cvo_bag_frames() {
  python3 - "$1" <<'PY'
import sys
import rosbag
with rosbag.Bag(sys.argv[1]) as bag:
    topics = bag.get_type_and_topic_info().topics
counts = [t.message_count for t in topics.values() if t.msg_type == "sensor_msgs/Image"]
if not counts:
    sys.exit("no image topics in " + sys.argv[1])
print(min(counts))
PY
}

# Poses in a TUM trajectory file (lines of 8 numbers; '#' comments do not count).
cvo_pose_count() { awk '!/^#/ && NF >= 8' "$1" | wc -l; }

# The first line of a roslaunch log that says why something failed (a Python exception, a died
# process, an ERROR or FATAL log line), shortened to 300 characters; empty when none.
cvo_first_error() {
  { grep -m1 -E '^[A-Za-z_.]*(Error|Exception)\b' "$1" ||
    grep -m1 -E '\[FATAL\]|has died|\[ERROR\]|ERROR:' "$1" || true; } |
    sed 's/\x1b\[[0-9;]*m//g' | cut -c1-300
}

# roslaunch ARGS... with its output in LOG, stopped (as Ctrl-C would) when a node logs FATAL (a
# nodelet that gives up, e.g. --backend cuda without a GPU, stays idle and a paced bag player
# would wait for it for ever), or when it has not ended after CVO_ROSLAUNCH_LIMIT seconds (900: a
# bound a slow or loaded machine does not reach; only a hang does, e.g. a player waiting for a
# subscriber that never comes). Returns roslaunch's status, 124 after the limit.
cvo_roslaunch_logged() {
  local log=$1 launch rc=0 start=$SECONDS limit=${CVO_ROSLAUNCH_LIMIT:-900}
  shift
  : >"$log"  # emptied here, before the loop reads it (not by the background job's redirection)
  roslaunch "$@" >>"$log" 2>&1 &
  launch=$!
  while kill -0 "$launch" 2>/dev/null; do
    if grep -q '\[FATAL\]' "$log"; then
      kill -INT "$launch" 2>/dev/null || true
      break
    fi
    if [ $((SECONDS - start)) -ge "$limit" ]; then
      echo "cvo_roslaunch_logged: not ended after $limit s: stopped (a hang)" >>"$log"
      kill -INT "$launch" 2>/dev/null || true
      wait "$launch" || true
      return 124
    fi
    sleep 1
  done
  wait "$launch" || rc=$?
  return "$rc"
}
