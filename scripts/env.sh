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
  cmake -S "$CVO_ROOT" -B "$CVO_BUILD" -DCMAKE_BUILD_TYPE=Release >"$CVO_BUILD/configure.log" 2>&1 ||
    { cat "$CVO_BUILD/configure.log"; return 1; }
  grep "cvo_odometry:" "$CVO_BUILD/configure.log" || true
}
