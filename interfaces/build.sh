#!/usr/bin/env bash
# Build the project's ROS 2 interface packages with the rosidl generators and ament_cmake from
# PyPI, and install them into a Python prefix (a venv):
#   rmf_lift_msgs     Open-RMF's LiftRequest/LiftState (not on PyPI; Apache-2.0, see its NOTICE.md)
#   pmnav_interfaces  the NavigateToRoom action
#
#   interfaces/build.sh [PREFIX]      # default: the .venv beside this folder
#
# Needs cmake (>= 3.21), a C/C++ compiler and the Python headers, plus the `ros` extra
# (rosidl generators, ament_cmake, catkin_pkg). The Python packages land in PREFIX's
# site-packages, their libraries in PREFIX/lib (on the path the ROS wheels' bootstrapper sets).
# PMNAV_INTERFACES_BUILD: the folder the builds and their logs go to (default: build/).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
prefix="$(cd "${1:-$here/../.venv}" && pwd)"
py="$prefix/bin/python"
builds="${PMNAV_INTERFACES_BUILD:-$here/../build}"
for tool in cmake cc c++; do
    command -v "$tool" >/dev/null || { echo "interfaces/build.sh: $tool not found (apt-get install cmake g++)" >&2; exit 1; }
done
export PATH="$prefix/bin:$PATH" AMENT_PREFIX_PATH="$prefix${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
mkdir -p "$builds"
start=$(date +%s)
# package:the import that proves it installed
for pkg in "rmf_lift_msgs:from rmf_lift_msgs.msg import LiftRequest, LiftState" \
           "pmnav_interfaces:from pmnav_interfaces.action import NavigateToRoom"; do
    name="${pkg%%:*}" check="${pkg#*:}" build="$builds/${pkg%%:*}"
    cmake -S "$here/$name" -B "$build" -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_INSTALL_PREFIX="$prefix" \
        -DPython3_EXECUTABLE="$py" -DBUILD_TESTING=OFF > "$build.log" 2>&1 \
        && cmake --build "$build" -j"$(nproc)" >> "$build.log" 2>&1 \
        && cmake --install "$build" >> "$build.log" 2>&1 \
        || { tail -30 "$build.log" >&2; echo "interfaces/build.sh: $name failed, log in $build.log" >&2; exit 1; }
    "$py" -c "$check" \
        || { echo "interfaces/build.sh: built, but $name does not import" >&2; exit 1; }
done
echo "rmf_lift_msgs and pmnav_interfaces built and installed into $prefix in $(( $(date +%s) - start )) s"
