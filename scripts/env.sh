# shellcheck shell=bash
# Sourced by scripts/*: puts the repo's .venv and the built ros_ws on the paths, as
# `source install/setup.bash` would on a full ROS install.
ML_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export ML_ROOT
ML_VENV="$ML_ROOT/.venv"
ML_INSTALL="$ML_ROOT/ros_ws/install"
export VIRTUAL_ENV="$ML_VENV"
export PATH="$ML_VENV/bin:$PATH"
export AMENT_PREFIX_PATH="$ML_INSTALL/multilift_learning:$ML_INSTALL/multilift_tools:$ML_INSTALL/multilift_control:$ML_INSTALL/multilift_sim:$ML_INSTALL/multilift_msgs:$ML_VENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$ML_VENV${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
for _pkg in multilift_msgs multilift_sim multilift_control multilift_tools multilift_learning; do
  PYTHONPATH="$ML_INSTALL/$_pkg/lib/python3.11/site-packages${PYTHONPATH:+:$PYTHONPATH}"
done
export LD_LIBRARY_PATH="$ML_INSTALL/multilift_msgs/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# tf2_msgs built from ros_ws/src/tf2_msgs_fallback where the environment has none (scripts/setup),
# last on the paths so an environment's own tf2_msgs wins. Added whether or not it is built yet:
# scripts/setup sources this file before its first build and imports tf2_msgs after it.
AMENT_PREFIX_PATH="$AMENT_PREFIX_PATH:$ML_INSTALL/tf2_msgs"
PYTHONPATH="$PYTHONPATH:$ML_INSTALL/tf2_msgs/lib/python3.11/site-packages"
LD_LIBRARY_PATH="$LD_LIBRARY_PATH:$ML_INSTALL/tf2_msgs/lib"
export PYTHONPATH
unset _pkg
