# Source this: the environment for building and running the workspace with the venv's ROS 2.
# The ROS 2 wheels install their ament prefix into the venv itself (.venv/share/...), so the
# venv is the underlay that colcon and CMake must search.
_repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export AMENT_PREFIX_PATH="$_repo/.venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$_repo/.venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
export PATH="$_repo/.venv/bin:$PATH"
# Python writes the byte code of what it imports, once, to the venv (not next to the sources),
# even where PYTHONDONTWRITEBYTECODE is set, as on our machines: every node process would
# otherwise compile rclpy, numpy and pybullet again (4.3 s instead of 1.5 s to import them).
# Compiling the whole venv ahead took 35 s of CPU, most of it for modules no program imports.
unset PYTHONDONTWRITEBYTECODE
export PYTHONPYCACHEPREFIX="$_repo/.venv/pycache"
# One BLAS thread per process, as stack.launch.py sets for the robot (README, "With a real
# driver"): OpenBLAS's extra threads spin after each call. A value set outside stays.
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
if [ -f "$_repo/ros2_ws/install/setup.bash" ]; then
  # colcon's setup scripts reference unset variables
  set +u
  . "$_repo/ros2_ws/install/setup.bash"
fi
unset _repo
