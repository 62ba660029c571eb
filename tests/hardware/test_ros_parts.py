"""The ROS front end's parts that need no running nodes: parameter checks, --record
parsing, the launcher's command lines, feedback from the blackboard, diagnostics levels,
MCAP schemas."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware import launcher
from pmnav_bt.hardware.node import PARAMETERS, split_record
from pmnav_bt.hardware.params import UnknownParameterError, check_unknown, usage, wants_help
from pmnav_bt.hardware.requests import progress, progress_line
from pmnav_bt.seams import Pose2D


class _Node:
    def __init__(self, overrides):
        self._parameter_overrides = overrides

    def get_name(self):
        return "pmnav"


def test_unknown_parameter_names_the_closest_known_one():
    check_unknown(_Node({"building": 1, "use_sim_time": 0}), PARAMETERS)
    with pytest.raises(UnknownParameterError, match="'bulding'.*did you mean 'building'"):
        check_unknown(_Node({"bulding": "x"}), PARAMETERS)
    with pytest.raises(UnknownParameterError, match="'zzz' for node 'pmnav' \\(--help"):
        check_unknown(_Node({"zzz": 1}), PARAMETERS)


def test_help_is_asked_before_ros_args_only():
    assert wants_help(["pmnav-ros", "--help"])
    assert not wants_help(["pmnav-ros", "--ros-args", "-p", "x:=--help"])
    text = usage("pmnav-ros", "summary", PARAMETERS, "example")
    assert "ready_timeout_s" in text and "hfov_deg" in text


def test_record_is_taken_out_of_the_rclpy_arguments():
    rec, rest = split_record(["p", "--record", "a.mcap", "--ros-args", "-p", "x:=1"])
    assert rec == "a.mcap" and rest == ["p", "--ros-args", "-p", "x:=1"]
    assert split_record(["p", "--record=b.mcap"]) == ("b.mcap", ["p"])
    with pytest.raises(PmNavError, match="FILE.mcap"):
        split_record(["p", "--record", "b.bag"])


def test_angle_parameters_are_radians_or_named_deg():
    for name, (_default, desc) in PARAMETERS.items():
        if "angle" in desc or "yaw" in name or "fov" in name:
            assert name.endswith("_deg") or "rad" in desc, name


def test_launcher_builds_the_launch_files_command_lines():
    v = launcher.parse(["start_pose:=47,20,0", "record:=r.mcap"])
    (sim_name, sim), (ctl_name, ctl) = launcher.commands(v)
    assert sim_name == "sim_create3" and "start_pose:='47,20,0'" in sim
    assert ctl_name == "pmnav" and ctl[ctl.index("--record") + 1] == "r.mcap"
    assert "segmentation_topic:='camera/segmentation'" in ctl
    # the controller's own parameters reach it: the web view's port as a number
    ctl = launcher.commands(launcher.parse(["view_port:=8765", "map_updates_dir:=u"]))[1][1]
    assert "view_port:=8765" in ctl and "map_updates_dir:='u'" in ctl
    assert [n for n, _ in launcher.commands(launcher.parse(["sim:=false"]))] == ["pmnav"]
    with pytest.raises(launcher.LaunchArgumentError, match="did you mean 'building'"):
        launcher.parse(["bulding:=x"])


def _plan():
    step = SimpleNamespace
    steps = (
        step(position=(10.0, 0.0), distance=10.0, target=None, text=lambda: "{a: go straight}"),
        step(position=(10.0, 5.0), distance=5.0, target=(11.0, 5.0), text=lambda: "{b: arrive}"),
    )
    return SimpleNamespace(steps=steps)


def test_progress_reads_step_distance_and_recoveries():
    bb = {"plan": _plan(), "map_T_odom": (0, 0, 0), "step_index": 0, "replans": 1}
    bb["fix_attempts"] = 2
    bb["level"] = "L2"
    p = progress(bb.get, Pose2D(4.0, 0.0, 0.0), 12.0)
    assert p["phase"] == "navigating" and (p["current_step"], p["step_count"]) == (1, 2)
    assert p["distance_remaining"] == pytest.approx(6.0 + 5.0 + 1.0)
    assert p["recoveries"] == 2 and p["step_text"] == "{a: go straight}"
    assert p["level"] == "L2"
    line = progress_line(p)
    assert "navigating, level L2, step 1/2 {a: go straight}, 12.0 m to go, 2 recoveries" in line
    p = progress({}.get, None, 1.0)
    assert p["phase"] == "localizing" and math.isnan(p["distance_remaining"])
    assert p["level"] == "" and "level" not in progress_line(p)  # one level: none named


def test_diagnostics_levels(ros_required):
    from diagnostic_msgs.msg import DiagnosticStatus

    from pmnav_bt.hardware.diagnostics import level_and_message

    missing = ["no odometry received on /odom"]
    assert level_and_message({"state": "idle", "missing": missing})[0] == DiagnosticStatus.WARN
    waiting = {"state": "running", "missing": missing, "fault": "x", "waiting_for_sensors": True}
    assert level_and_message(waiting)[0] == DiagnosticStatus.WARN
    running = {"state": "running", "missing": missing, "fault": "SENSOR_TIMEOUT: x"}
    assert level_and_message(running)[0] == DiagnosticStatus.ERROR
    assert level_and_message({"state": "idle", "missing": []}) == (DiagnosticStatus.OK, "ready")


def test_mcap_schema_has_every_dependency_once(ros_required):
    from mcap_ros2._dynamic import generate_dynamic

    from pmnav_bt.hardware.recorder import schema_text

    text = schema_text("nav_msgs/msg/Path")
    deps = [ln for ln in text.splitlines() if ln.startswith("MSG: ")]
    assert len(deps) == len(set(deps))
    assert {"MSG: std_msgs/Header", "MSG: geometry_msgs/PoseStamped"} <= set(deps)
    assert "nav_msgs/msg/Path" in generate_dynamic("nav_msgs/msg/Path", text)
