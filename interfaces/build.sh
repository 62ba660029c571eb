#!/usr/bin/env bash
# Build the ROS 2 interface package pmnav_interfaces (the NavigateToRoom action) with the
# rosidl generators and ament_cmake from PyPI, and install it into a Python prefix (a venv).
#
#   interfaces/build.sh [PREFIX]      # default: the .venv beside this folder
#
# Needs cmake (>= 3.21), a C/C++ compiler and the Python headers, plus the `ros` extra
# (rosidl generators, ament_cmake, catkin_pkg). The Python package lands in PREFIX's
# site-packages, its libraries in PREFIX/lib (on the path the ROS wheels' bootstrapper sets).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
prefix="$(cd "${1:-$here/../.venv}" && pwd)"
py="$prefix/bin/python"
build="${PMNAV_INTERFACES_BUILD:-$here/../build/pmnav_interfaces}"
for tool in cmake cc c++; do
    command -v "$tool" >/dev/null || { echo "interfaces/build.sh: $tool not found (apt-get install cmake g++)" >&2; exit 1; }
done
export PATH="$prefix/bin:$PATH" AMENT_PREFIX_PATH="$prefix${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
mkdir -p "$(dirname "$build")"
start=$(date +%s)
cmake -S "$here/pmnav_interfaces" -B "$build" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_INSTALL_PREFIX="$prefix" \
    -DPython3_EXECUTABLE="$py" -DBUILD_TESTING=OFF > "$build.log" 2>&1 \
    && cmake --build "$build" -j"$(nproc)" >> "$build.log" 2>&1 \
    && cmake --install "$build" >> "$build.log" 2>&1 \
    || { tail -30 "$build.log" >&2; echo "interfaces/build.sh: failed, log in $build.log" >&2; exit 1; }
"$py" -c "from pmnav_interfaces.action import NavigateToRoom" \
    || { echo "interfaces/build.sh: built, but pmnav_interfaces does not import" >&2; exit 1; }
echo "pmnav_interfaces built and installed into $prefix in $(( $(date +%s) - start )) s"
