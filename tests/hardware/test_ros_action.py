"""The navigate_to_room action, readiness, goal_pose, /diagnostics and --record, over DDS.

``pmnav-launch`` (the launcher that does what launch/pmnav.launch.py does) starts the
simulated Create 3 and pmnav-ros as processes in a private domain; this process is
the action client and a probe. One launch serves the tests of ``TestLaunched``
(module scope): an unknown room, a goal to success with feedback at least once a
second, a cancel mid-way (the base stops), then the MCAP recording of that run.
"""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import time

import pytest

from pmnav_bt.hardware.action_server import action_type
from pmnav_bt.hardware.env import ros_env
from pmnav_bt.hardware.testing import Proc

pytestmark = [
    pytest.mark.timeout(300),
    pytest.mark.skipif(action_type() is None, reason="pmnav_interfaces not built"),
]
READY_S = 60.0
GOAL_NEAR = "One-Stop Service Centre"  # ~5 m from 47,20,0
GOAL_FAR = "room1"


class ActionClient:
    """An rclpy action client in this process, spun in the background."""

    def __init__(self, runtime):
        from rclpy.node import Node

        from pmnav_bt.hardware.action_client import ThreadSafeActionClient

        self.node = Node("action_test_client", context=runtime.context)
        self.type = action_type()
        self.client = ThreadSafeActionClient(self.node, self.type, "navigate_to_room")
        runtime.add(self.node)

    def send(self, room: str = "", pose=None, frame: str = "map"):
        goal = self.type.Goal(room=room)
        if pose is not None:
            goal.pose.header.frame_id = frame
            goal.pose.pose.position.x, goal.pose.pose.position.y = pose
        feedback: list[tuple[float, object]] = []
        fut = self.client.send_goal_async(
            goal, feedback_callback=lambda m: feedback.append((time.monotonic(), m.feedback))
        )
        _wait(fut.done, 10.0, "goal acceptance")
        handle = fut.result()
        assert handle.accepted
        return handle, handle.get_result_async(), feedback


def _wait(pred, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


@pytest.fixture(scope="module")
def launched(tmp_path_factory, new_domain_id):
    from pmnav_bt.hardware.runtime import RosRuntime
    from pmnav_bt.hardware.testing import Probe

    tmp = tmp_path_factory.mktemp("launch")
    domain = new_domain_id()  # a hash could land on a domain an earlier test still uses
    record = tmp / "run.mcap"
    log = open(tmp / "launch.log", "w", encoding="utf-8")  # noqa: SIM115
    launcher = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pmnav_bt.hardware.launcher",
            "start_pose:=47,20,0",
            "width:=240",
            "height:=180",
            f"record:={record}",
            "overrides:=grounder.backend=sim_gt",  # the oracle (the simulator's labels)
        ],  # fmt: skip
        env=ros_env(domain_id=domain),
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    rt = RosRuntime(args=[], domain_id=domain)
    probe = Probe(rt)
    client = ActionClient(rt)
    rt.start()
    state = {"launcher": launcher, "log": tmp / "launch.log", "record": record, "probe": probe}
    try:
        assert client.client.wait_for_server(timeout_sec=READY_S), (tmp / "launch.log").read_text()
        yield client, state
    finally:
        rt.shutdown()
        if launcher.poll() is None:
            launcher.send_signal(signal.SIGINT)
            try:
                launcher.wait(20)
            except subprocess.TimeoutExpired:
                launcher.kill()
        log.close()


def _result(res_future, timeout: float, state):
    _wait(res_future.done, timeout, f"the result\n{state['log'].read_text()[-3000:]}")
    return res_future.result()


class TestLaunched:
    def test_unknown_room_is_an_error_code_and_message(self, launched):
        from action_msgs.msg import GoalStatus

        client, state = launched
        _, res, _ = client.send(room="Hall of Mirrors")
        r = _result(res, 90.0, state)
        assert r.status == GoalStatus.STATUS_ABORTED
        assert r.result.error_code == client.type.Result.INVALID_GOAL
        assert r.result.failure_code == "INVALID_GOAL"
        assert "Hall of Mirrors" in r.result.error_msg

    def test_pose_in_another_frame_is_rejected(self, launched):
        client, state = launched
        _, res, _ = client.send(pose=(47.0, 22.0), frame="odom")
        r = _result(res, 30.0, state)
        assert r.result.error_code == client.type.Result.INVALID_GOAL
        assert "frame 'odom'" in r.result.error_msg

    def test_goal_succeeds_with_feedback_every_second(self, launched):
        from action_msgs.msg import GoalStatus

        client, state = launched
        _, res, feedback = client.send(room=GOAL_NEAR)
        r = _result(res, 200.0, state)
        assert r.status == GoalStatus.STATUS_SUCCEEDED, r.result.error_msg
        assert r.result.error_code == client.type.Result.NONE
        assert r.result.room_id == "room17" and r.result.room_name == GOAL_NEAR
        times = [t for t, _ in feedback]
        assert len(times) >= 3
        gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
        assert max(gaps) <= 1.0, f"feedback gaps up to {max(gaps):.2f} s"
        phases = {fb.phase for _, fb in feedback}
        assert "navigating" in phases
        nav = [fb for _, fb in feedback if fb.phase == "navigating"]
        assert nav[0].step_count >= 1 and nav[0].current_step >= 1
        assert nav[-1].distance_remaining < nav[0].distance_remaining
        assert {fb.level for _, fb in feedback} == {""}  # one level: no level named
        state["succeeded"] = True

    def test_cancel_midway_stops_the_base(self, launched):
        from action_msgs.msg import GoalStatus

        client, state = launched
        probe = state["probe"]
        handle, res, feedback = client.send(room=GOAL_FAR)
        probe.wait_for(
            lambda: any(c[1] > 0.0 for c in list(probe.cmd)[-5:]), 120.0, "the base to drive"
        )
        t_cancel = time.monotonic()
        cancel = handle.cancel_goal_async()
        _wait(cancel.done, 10.0, "the cancel response")
        r = _result(res, 30.0, state)
        assert r.status == GoalStatus.STATUS_CANCELED
        assert r.result.error_code == client.type.Result.CANCELLED
        probe.wait_for(
            lambda: probe.cmd and probe.cmd[-1][0] > t_cancel and probe.cmd[-1][1:] == (0.0, 0.0),
            2.0,
            "a zero cmd_vel after the cancel",
        )
        time.sleep(1.0)
        with probe.lock:
            moving = [c for c in probe.cmd if c[0] > t_cancel + 0.5 and (c[1] or c[2])]
        assert not moving, f"cmd_vel still moving after the cancel: {moving[:3]}"
        probe.wait_for(
            lambda: probe.stats is not None and probe.stats["command"] == [0.0, 0.0],
            3.0,
            "the simulated base to stop",
        )

    def test_goal_pose_goes_to_the_nearest_door(self, launched):
        """RViz's 2D Goal Pose on goal_pose, 0.5 m from room17's door: the run's goal is
        room17 (cancelled at once; the result topic says so)."""
        from geometry_msgs.msg import PoseStamped
        from std_msgs.msg import Empty

        from pmnav_bt.hardware import qos
        from pmnav_bt.map.catalogue import load_building

        client, state = launched
        probe = state["probe"]
        door = load_building("fig2_hospital").room("room17").door
        pub = probe.node.create_publisher(PoseStamped, "goal_pose", qos.events())
        cancel = probe.node.create_publisher(Empty, "cancel", qos.events())
        _wait(lambda: pub.get_subscription_count() > 0, 10.0, "the goal_pose subscriber")
        msg = PoseStamped()
        msg.header.frame_id = "map"
        msg.pose.position.x, msg.pose.position.y = door[0] + 0.5, door[1]
        msg.pose.orientation.w = 1.0
        n = len(probe.results)
        pub.publish(msg)
        probe.wait_for(lambda: probe.status and probe.status["goal"] == "room17", 10.0, "run")
        cancel.publish(Empty())
        r = probe.wait_for(lambda: probe.results[n:] and probe.results[-1], 30.0, "the result")
        assert r["goal"] == "room17" and r["code"] == "CANCELLED"

    def test_diagnostics_and_status_report_ready(self, launched):
        _, state = launched
        probe = state["probe"]
        with probe.lock:
            probe.status = None
        probe.wait_for(lambda: probe.status is not None, 5.0, "a status")
        assert probe.status["ready"] is True and probe.status["missing"] == []

    def test_the_recording_reads_back(self, launched):
        """Last: stops the launcher (SIGINT), then reads the MCAP with mcap_ros2."""
        from mcap_ros2.reader import read_ros2_messages

        client, state = launched
        if not state.get("succeeded"):
            _, res, _ = client.send(room=GOAL_NEAR)
            _result(res, 200.0, state)
        launcher = state["launcher"]
        launcher.send_signal(signal.SIGINT)
        assert launcher.wait(30) == 0, state["log"].read_text()[-3000:]
        log = state["log"].read_text()
        assert "[launcher] pmnav exited with 0" in log
        assert "[launcher] sim_create3 exited with 0" in log
        counts: dict[str, int] = {}
        first: dict[str, object] = {}
        for m in read_ros2_messages(str(state["record"])):
            counts[m.channel.topic] = counts.get(m.channel.topic, 0) + 1
            first.setdefault(m.channel.topic, m.ros_msg)
        topics = ("/camera/image_raw", "/odom", "/cmd_vel", "/plan", "/trajectory", "/markers",
                  "/tree", "/tree/structure", "/diagnostics", "/result")  # fmt: skip
        for topic in topics:
            assert counts.get(topic, 0) >= 1, f"{topic} not recorded: {counts}"
        assert counts["/odom"] > 50 and counts["/tree"] > 50
        img = first["/camera/image_raw"]
        assert (img.width, img.height, img.encoding) == (240, 180, "rgb8")
        assert len(img.data) == 240 * 180 * 3
        assert len(first["/plan"].poses) >= 2
        assert json.loads(first["/tree/structure"].data)["type"] == "tree"
        diag = first["/diagnostics"].status[0]
        assert diag.name == "pmnav: controller"


def test_goal_before_sensors_waits_then_names_the_missing_input(domain_id, tmp_path):
    """No simulator: a goal waits ``ready_timeout_s`` and fails naming both inputs; the
    diagnostics say WARN and which input is missing."""
    from diagnostic_msgs.msg import DiagnosticArray

    from pmnav_bt.hardware import qos
    from pmnav_bt.hardware.runtime import RosRuntime

    ctl = Proc(
        "pmnav_bt.hardware.node",
        {"building": "fig2_hospital", "ready_timeout_s": 3.0},
        domain_id,
        tmp_path / "controller.log",
    )
    rt = RosRuntime(args=[], domain_id=domain_id)
    client = ActionClient(rt)
    diags: list = []
    client.node.create_subscription(DiagnosticArray, "/diagnostics", diags.append, qos.events())
    rt.start()
    try:
        assert client.client.wait_for_server(timeout_sec=READY_S), ctl.tail()
        t0 = time.monotonic()
        _, res, feedback = client.send(room=GOAL_NEAR)
        _wait(res.done, 30.0, "the result")
        r = res.result().result
        assert time.monotonic() - t0 >= 2.5  # it waited, not failed at once
        assert r.error_code == client.type.Result.SENSOR_TIMEOUT
        assert "not ready after 3 s" in r.error_msg
        assert "no odometry received on /odom" in r.error_msg
        assert "no camera frame received on /camera/image_raw" in r.error_msg
        assert feedback and feedback[0][1].phase == "waiting_for_sensors"
        diags.clear()  # one published after the result: idle, not ready
        _wait(lambda: diags, 5.0, "/diagnostics")
        st = diags[-1].status[0]
        assert st.level == b"\x01" and "no odometry received on /odom" in st.message
    finally:
        rt.shutdown()
        ctl.stop()


def test_unknown_parameter_names_the_closest(domain_id, tmp_path):
    ctl = Proc(
        "pmnav_bt.hardware.node", {"bulding": "fig2_hospital"}, domain_id, tmp_path / "c.log"
    )
    assert ctl.proc.wait(120) == 1
    ctl.stop()
    text = (tmp_path / "c.log").read_text()
    assert "unknown parameter 'bulding'" in text and "did you mean 'building'?" in text
    assert "Traceback" not in text


@pytest.mark.parametrize(
    "module",
    [
        "pmnav_bt.hardware.node",
        "pmnav_bt.hardware.sim_create3",
        "pmnav_bt.hardware.goal",
        "pmnav_bt.hardware.launcher",
        "pmnav_bt.hardware.sim_lift_node",
    ],  # fmt: skip
)
def test_help_prints_usage_without_starting_a_node(module, ros_required):
    out = subprocess.run(
        [sys.executable, "-m", module, "--help"],
        env=ros_env(domain_id=57),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    assert "usage" in out.stdout.lower() or "arguments" in out.stdout
    assert "[INFO]" not in out.stdout + out.stderr  # no node logged anything


def test_room_near_pose():
    from pmnav_bt.hardware.requests import GoalPoseError, goal_from_pose
    from pmnav_bt.map.catalogue import load_building

    b = load_building("fig2_hospital")
    door = b.room("room17").door
    room, dist = goal_from_pose(b, "map", door[0] + 0.3, door[1] - 0.2, "map")
    assert room.id == "room17" and dist == pytest.approx(math.hypot(0.3, 0.2))
    with pytest.raises(GoalPoseError, match="frame 'base_link'"):
        goal_from_pose(b, "base_link", 0.0, 0.0, "map")
