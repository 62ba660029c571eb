#!/usr/bin/env bash
# Build the ROS 2 interface packages in this folder with the rosidl generators and
# ament_cmake from PyPI, and install them into a Python prefix (a venv).
#
#   interfaces/build.sh [PREFIX [PACKAGE...]]   # default: the .venv beside this folder, all
#
# Needs cmake (>= 3.21), a C/C++ compiler and the Python headers, plus the `ros` extra
# (rosidl generators, ament_cmake, catkin_pkg). The Python packages land in PREFIX's
# site-packages, their libraries in PREFIX/lib (on the path the ROS wheels' bootstrapper
# sets). Each package is built on its own: one that fails is named at the end (exit 1),
# and the others are installed all the same. PMNAV_INTERFACES_BUILD: the folder the
# builds and their logs go to (default: build/).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
prefix="$(cd "${1:-$here/../.venv}" && pwd)"
py="$prefix/bin/python"
builds="${PMNAV_INTERFACES_BUILD:-$here/../build}"
# The packages, built in this order (a folder here each):
packages=(
    rmf_lift_msgs       # Open-RMF's LiftRequest/LiftState (Apache-2.0, see its NOTICE.md)
    pmnav_interfaces    # the NavigateToRoom action
    irobot_create_msgs  # the Create 3's hazard messages (iRobot's definitions, BSD-3-Clause)
)
if [ $# -gt 1 ]; then
    packages=("${@:2}")
fi
for tool in cmake cc c++; do
    command -v "$tool" >/dev/null || { echo "interfaces/build.sh: $tool not found (apt-get install cmake g++)" >&2; exit 1; }
done
export PATH="$prefix/bin:$PATH" AMENT_PREFIX_PATH="$prefix${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
mkdir -p "$builds"
failed=()
for pkg in "${packages[@]}"; do
    [ -f "$here/$pkg/CMakeLists.txt" ] \
        || { echo "interfaces/build.sh: no package '$pkg' in $here" >&2; failed+=("$pkg"); continue; }
    build="$builds/$pkg"
    start=$(date +%s)
    if ! { cmake -S "$here/$pkg" -B "$build" -DCMAKE_BUILD_TYPE=Release \
            -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_INSTALL_PREFIX="$prefix" \
            -DPython3_EXECUTABLE="$py" -DBUILD_TESTING=OFF > "$build.log" 2>&1 \
        && cmake --build "$build" -j"$(nproc)" >> "$build.log" 2>&1 \
        && cmake --install "$build" >> "$build.log" 2>&1; }; then
        tail -30 "$build.log" >&2
        echo "interfaces/build.sh: $pkg failed, log in $build.log" >&2
        failed+=("$pkg")
        continue
    fi
    # The generated Python modules import (msg, srv, action: whichever the package has).
    modules=()
    for kind in msg srv action; do
        [ -d "$here/$pkg/$kind" ] && modules+=("$pkg.$kind")
    done
    if ! "$py" -c "import importlib, sys; [importlib.import_module(m) for m in sys.argv[1:]]" "${modules[@]}"; then
        echo "interfaces/build.sh: $pkg built, but ${modules[*]} does not import" >&2
        failed+=("$pkg")
        continue
    fi
    echo "$pkg built and installed into $prefix in $(( $(date +%s) - start )) s"
done
if [ ${#failed[@]} -gt 0 ]; then
    echo "interfaces/build.sh: not built: ${failed[*]}" >&2
    exit 1
fi
