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
