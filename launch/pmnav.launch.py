"""ROS 2 launch file: PM-Nav against the simulated Create 3, or against a real one.

    ros2 launch launch/pmnav.launch.py                       # simulator + controller
    ros2 launch launch/pmnav.launch.py sim:=false \\
        image_topic:=/camera/color/image_raw camera_info_topic:=/camera/color/camera_info \\
        depth_topic:=/camera/aligned_depth_to_color/image_raw segmentation_topic:=''

Needs the ROS 2 launch packages (``launch``, ``launch_ros``, ``ros2launch``), which the
PyPI wheels this project installs do not include: run it on a ROS 2 Jazzy install
(``source /opt/ros/jazzy/setup.bash``) with this project pip-installed into that
Python, or start the two console scripts by hand (docs/ros2.md). The nodes are the
console scripts ``pmnav-sim-create3`` and ``pmnav-ros`` (``ExecuteProcess``: they are
pip entry points, not ament packages).
"""

from __future__ import annotations

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, LogInfo
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration

ARGS = {
    "sim": ("true", "start pmnav-sim-create3 (false: a real Create 3 and camera)"),
    "building": ("fig2_hospital", "building file (YAML) or built-in name"),
    "start_pose": ("", "simulator start x,y,yaw_deg (empty: the building's start)"),
    "width": ("320", "simulated camera width"),
    "height": ("240", "simulated camera height"),
    "camera_rate_hz": ("5.0", "simulated camera rate"),
    "config": ("", "PM-Nav config file"),
    "overrides": ("", "config overrides 'section.key=value;...'"),
    "namespace": ("/", "robot namespace (a Create 3's, e.g. /robot1)"),
    "image_topic": ("camera/image_raw", ""),
    "camera_info_topic": ("camera/camera_info", ""),
    "depth_topic": ("camera/depth/image_raw", ""),
    "segmentation_topic": ("camera/segmentation", "empty on a real robot"),
    "tree_log": ("", "also write tree snapshots (JSON lines) here"),
}


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
        cmd=["pmnav-sim-create3"]
        + _ros_args(
            "sim_create3", ["building", "start_pose"], ("width", "height", "camera_rate_hz")
        ),
        name="sim_create3",
        output="screen",
        condition=IfCondition(LaunchConfiguration("sim")),
    )
    controller = ExecuteProcess(
        cmd=["pmnav-ros"]
        + _ros_args(
            "pmnav",
            [
                "building",
                "config",
                "overrides",
                "image_topic",
                "camera_info_topic",
                "depth_topic",
                "segmentation_topic",
                "tree_log",
            ],
        ),
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
