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

# Installs what is missing and configures the ROS build in $CVO_BUILD (log: configure.log).
cvo_configure() {
  "$CVO_ROOT/scripts/install_deps.sh" full
  mkdir -p "$CVO_BUILD"
  # device_cpu ON: the device code's tests must run, never be skipped for want of Thrust.
  cmake -S "$CVO_ROOT" -B "$CVO_BUILD" -DCMAKE_BUILD_TYPE=Release -DCVO_WITH_DEVICE_CPU=ON \
    >"$CVO_BUILD/configure.log" 2>&1 ||
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
