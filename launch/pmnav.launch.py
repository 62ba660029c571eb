"""ROS 2 launch file: PM-Nav against the simulated Create 3, or against a real one.

    ros2 launch launch/pmnav.launch.py                       # simulator + controller
    ros2 launch launch/pmnav.launch.py sim:=false \\
        image_topic:=/camera/color/image_raw camera_info_topic:=/camera/color/camera_info \\
        depth_topic:=/camera/aligned_depth_to_color/image_raw segmentation_topic:=''

Needs the ROS 2 launch packages (``launch``, ``launch_ros``, ``ros2launch``), which the
PyPI wheels this project installs do not include: run it on a ROS 2 Jazzy install
(``source /opt/ros/jazzy/setup.bash``) with this project pip-installed into that
Python. Without them, ``pmnav-launch`` (same arguments) starts the same processes. The nodes are the
console scripts ``pmnav-sim-create3`` and ``pmnav-ros`` (``ExecuteProcess``: they are
pip entry points, not ament packages).
"""

from __future__ import annotations

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, LogInfo
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration

from pmnav_bt.hardware.launcher import ARGS as LAUNCHER_ARGS
from pmnav_bt.hardware.launcher import (
    CONTROLLER_NUMBERS,
    CONTROLLER_STRINGS,
    SIM_NUMBERS,
    SIM_STRINGS,
)

# The arguments and the parameters each node gets are shared with ``pmnav-launch``
# (pmnav_bt/hardware/launcher.py), the launcher that runs without the launch packages
# (it is what the tests run).
ARGS = {k: v for k, v in LAUNCHER_ARGS.items() if k != "record"}


def _ros_args(node: str, strings: list[str], numbers: tuple[str, ...] = ()) -> list:
    """``--ros-args`` for ``node``. String values are YAML-quoted: rcl cannot parse an
    empty ``-p name:=``, and a quoted value always stays a string."""
    ns = LaunchConfiguration("namespace")
    cmd: list = ["--ros-args", "-r", ["__node:=", node], "-r", ["__ns:=", ns]]
    for p in strings:
        cmd += ["-p", [p, ":='", LaunchConfiguration(p), "'"]]
    for p in numbers:
        cmd += ["-p", [p, ":=", LaunchConfiguration(p)]]
    return cmd


def generate_launch_description() -> LaunchDescription:
    decls = [DeclareLaunchArgument(k, default_value=v, description=d) for k, (v, d) in ARGS.items()]
    sim = ExecuteProcess(
        cmd=["pmnav-sim-create3"] + _ros_args("sim_create3", list(SIM_STRINGS), SIM_NUMBERS),
        name="sim_create3",
        output="screen",
        condition=IfCondition(LaunchConfiguration("sim")),
    )
    controller = ExecuteProcess(
        cmd=["pmnav-ros"] + _ros_args("pmnav", list(CONTROLLER_STRINGS), CONTROLLER_NUMBERS),
        name="pmnav",
        output="screen",
        # SIGINT first: pmnav-ros sends a zero cmd_vel before it exits.
        sigterm_timeout="5",
    )
    return LaunchDescription(
        decls
        + [
            LogInfo(msg=["PM-Nav: send a room name on the goal topic, results on result"]),
            sim,
            controller,
        ]
    )
