"""The Create 3's hazard topic over Fast DDS: the simulated Create 3 publishes its bumps,
and the body in this process stops on them, and on a hazard a test publisher sends.

The body (``Create3Base``) runs on a node of this process against
``pmnav_bt.hardware.sim_create3`` started as a subprocess in a private domain
(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST). fig2_hospital's corridor at x = 47 runs along
x with its north wall 1.22 m from y = 20.
"""

from __future__ import annotations

import math
import time

import pytest

from pmnav_bt.hardware.hazards import message_types
from pmnav_bt.hardware.testing import Proc

pytestmark = pytest.mark.timeout(120)
needs_messages = pytest.mark.skipif(
    message_types() is None, reason="irobot_create_msgs not built (interfaces/build.sh)"
)

BUILDING = "fig2_hospital"
READY_S = 45.0  # process start (imports, pybullet world) on a busy 2-core machine
NORTH_WALL_Y = 21.2  # the corridor's north wall at x = 47


class _Rig:
    """The simulated Create 3 at ``start`` (x, y, yaw_deg in the map), and a body on it."""

    def __init__(self, domain_id: int, tmp_path, start: tuple[float, float, float]):
        from rclpy.node import Node

        from pmnav_bt.hardware.create3 import Create3Base
        from pmnav_bt.hardware.runtime import RosRuntime
        from pmnav_bt.hardware.testing import Probe

        self.start = start
        self.sim = Proc(
            "pmnav_bt.hardware.sim_create3",
            {
                "building": BUILDING,
                "start_pose": ",".join(str(v) for v in start),
                "width": 96,
                "height": 72,
                "odometry_noise": 0.0,
            },
            domain_id,
            tmp_path / "sim.log",
        )
        self.rt = RosRuntime(args=[], domain_id=domain_id)
        self.probe = Probe(self.rt)
        self.node = Node("hazard_test", context=self.rt.context)
        self.base = Create3Base(self.node)
        self.rt.add(self.node)
        self.rt.start()

    def ready(self) -> None:
        deadline = time.monotonic() + READY_S
        while self.base.fault() is not None:
            assert time.monotonic() < deadline and self.sim.alive(), (
                f"{self.base.fault()}\n{self.sim.tail()}"
            )
            time.sleep(0.1)

    def wait_status(self, status, timeout: float) -> float:
        """Wait until the body's motion status is ``status``; the time seen (system clock,
        as DDS stamps what it sends)."""
        deadline = time.monotonic() + timeout
        while self.base.motion_status() != status:
            assert time.monotonic() < deadline, (
                f"still {self.base.motion_status().value} after {timeout} s\n{self.sim.tail()}"
            )
            time.sleep(0.01)
        return time.time()

    def to_map(self, point: tuple[float, float]) -> tuple[float, float]:
        """An odometry point in the map (the odometry frame starts at the start pose)."""
        from pmnav_bt.geometry import se2_apply

        x, y, yaw_deg = self.start
        return tuple(se2_apply((x, y, math.radians(yaw_deg)), point))

    def moving_after(self, t: float) -> list:
        """The motion commands sent after ``t`` (system clock: when DDS says they were
        written, not when this busy process got round to them)."""
        with self.probe.lock:
            sent = zip(self.probe.cmd, self.probe.cmd_dds, strict=True)
            return [(src, v, w) for (_, v, w), (src, _) in sent if src > t and (v or w)]

    def close(self) -> None:
        self.base.close()
        self.rt.shutdown()
        self.sim.stop()


@needs_messages
def test_driving_into_a_wall_the_body_stops_on_the_bump_and_names_its_side(domain_id, tmp_path):
    """Heading 54 deg, the north wall comes 36 deg left of ahead: the front-left zone."""
    from pmnav_bt.hazards import HazardKind
    from pmnav_bt.seams import MotionStatus

    rig = _Rig(domain_id, tmp_path, (47.0, 20.4, 54.0))
    try:
        rig.ready()
        rig.base.set_velocity(0.3, 0.0)
        t_blocked = rig.wait_status(MotionStatus.BLOCKED, 10.0)
        # While the bumper is pressed forwards is refused.
        rig.base.set_velocity(0.2, 0.0)
        assert rig.base.motion_status() == MotionStatus.BLOCKED
        assert rig.base.velocity_command == (0.0, 0.0)
        bump = rig.base.blocked_by()
        assert bump is not None and bump.kind == HazardKind.BUMP, bump
        assert bump.frame == "bump_front_left" and bump.side == "front left"
        assert bump.describe().startswith("bumped front left at (")
        # Where the bumper touched: on the wall, in the odometry frame.
        assert rig.to_map(bump.point)[1] == pytest.approx(NORTH_WALL_Y, abs=0.05)
        assert bump in rig.base.hazards()
        # Stopped at once: no motion command was sent after the bump stopped it.
        time.sleep(0.3)
        assert not rig.moving_after(t_blocked), rig.moving_after(t_blocked)
        assert rig.probe.true_pose[1] == pytest.approx(NORTH_WALL_Y - 0.17, abs=0.01)
        # Pushed on regardless (cmd_vel from elsewhere), the wheels stall: the simulated
        # Create 3 reports both, with the bump.
        from geometry_msgs.msg import Twist, Vector3

        from pmnav_bt.hardware import qos

        seen: list[set] = []
        rig.probe.node.create_subscription(
            message_types()[0],
            "hazard_detection",
            lambda m: seen.append({(d.type, d.header.frame_id) for d in m.detections}),
            qos.sensor(),
        )
        push = rig.probe.node.create_publisher(Twist, "cmd_vel", qos.command())
        for _ in range(24):  # 1.2 s: the stall is felt after 0.5 s
            push.publish(Twist(linear=Vector3(x=0.2)))
            time.sleep(0.05)
        stall = {(1, "bump_front_left"), (3, "left_wheel"), (3, "right_wheel")}
        assert any(stall <= felt for felt in seen[-5:]), seen[-5:]
        time.sleep(0.6)  # the simulated robot's cmd_vel timeout: the push is over
        # Backing off the wall is allowed, and clears what blocked the body.
        rig.base.set_velocity(-0.1, 0.0)
        assert rig.base.motion_status() == MotionStatus.MOVING
        assert rig.base.blocked_by() is None
        rig.base.stop()
    finally:
        rig.close()


@needs_messages
def test_a_hazard_from_another_publisher_stops_a_moving_body(domain_id, tmp_path):
    """A bump while driving (BLOCKED), then a cliff while turning on the spot (FAULT: no
    motion at all), both from a test publisher on hazard_detection."""
    from pmnav_bt.hardware import qos
    from pmnav_bt.hardware.hazards import TYPE_CODES, vector_message
    from pmnav_bt.hazards import HazardKind
    from pmnav_bt.seams import MotionStatus

    rig = _Rig(domain_id, tmp_path, (47.0, 20.0, 0.0))  # along the corridor: 15 m free
    types = message_types()
    pub = rig.probe.node.create_publisher(types[0], "hazard_detection", qos.hazards())

    def send(kind: HazardKind, frame: str) -> None:
        stamp = rig.probe.node.get_clock().now().to_msg()
        pub.publish(vector_message(types, [(TYPE_CODES[kind], frame)], stamp, "base_link"))

    try:
        rig.ready()
        rig.base.set_velocity(0.2, 0.0)
        rig.probe.wait_for(lambda: rig.moving_after(0.0), 5.0, "the body to drive", (rig.sim,))
        send(HazardKind.BUMP, "bump_front_center")
        t_bump = rig.wait_status(MotionStatus.BLOCKED, 2.0)
        assert rig.base.blocked_by().frame == "bump_front_center"
        time.sleep(0.2)
        assert not rig.moving_after(t_bump)

        time.sleep(0.4)  # the bumper released (BUMP_HOLD_S)
        rig.base.set_velocity(0.0, 1.0)
        assert rig.base.motion_status() == MotionStatus.MOVING
        send(HazardKind.CLIFF, "cliff_side_left")
        t_cliff = rig.wait_status(MotionStatus.FAULT, 2.0)
        cliff = rig.base.blocked_by()
        assert cliff.kind == HazardKind.CLIFF and cliff.describe().startswith("cliff left at (")
        rig.base.set_velocity(-0.1, 0.0)  # nothing moves while the cliff is felt
        assert rig.base.velocity_command == (0.0, 0.0)
        time.sleep(0.2)
        assert not rig.moving_after(t_cliff)
        assert [h.kind for h in rig.base.hazards()] == [HazardKind.BUMP, HazardKind.CLIFF]
    finally:
        rig.close()


def test_without_the_messages_the_body_feels_nothing_and_says_so(
    domain_id, monkeypatch, capfd
):
    from rclpy.node import Node

    from pmnav_bt.hardware import create3
    from pmnav_bt.hardware.runtime import RosRuntime

    monkeypatch.setattr(create3, "message_types", lambda: None)  # as where it was not built
    rt = RosRuntime(args=[], domain_id=domain_id)
    node = Node("no_hazards", context=rt.context)
    base = create3.Create3Base(node)
    try:
        assert not base.hazards_enabled
        assert base.hazards() == [] and base.blocked_by() is None
        assert not [t for t, _ in node.get_subscriber_names_and_types_by_node(
            "no_hazards", "/") if "hazard" in t]  # fmt: skip
    finally:
        base.close()
        rt.shutdown()
    err = capfd.readouterr().err
    assert err.count("irobot_create_msgs is not built (interfaces/build.sh)") == 1, err


@needs_messages
def test_a_cliff_ends_the_controller_s_mission_naming_it(probe, domain_id, tmp_path):
    """The whole controller: a cliff felt while it drives to a goal stops the robot and the
    result is BASE_FAULT, its message naming the cliff."""
    from pmnav_bt.hardware import qos
    from pmnav_bt.hardware.hazards import TYPE_CODES, vector_message
    from pmnav_bt.hazards import HazardKind

    sim = Proc(
        "pmnav_bt.hardware.sim_create3",
        {"building": BUILDING, "start_pose": "47,20,180", "width": 160, "height": 120},
        domain_id,
        tmp_path / "sim.log",
    )
    ctl = Proc(
        "pmnav_bt.hardware.node",
        {"building": BUILDING, "overrides": "grounder.backend=sim_gt"},
        domain_id,
        tmp_path / "controller.log",
    )
    procs = (sim, ctl)
    types = message_types()
    pub = probe.node.create_publisher(types[0], "hazard_detection", qos.hazards())
    try:
        probe.wait_for(
            lambda: probe.status is not None and probe.status["ready"], READY_S, "ready", procs
        )
        t0 = time.monotonic()
        probe.send_goal("room17")
        probe.wait_for(
            lambda: [c for c in probe.cmd if c[0] > t0 and (c[1] or c[2])], 20.0, "motion", procs
        )
        stamp = probe.node.get_clock().now().to_msg()
        cliff = [(TYPE_CODES[HazardKind.CLIFF], "cliff_front_left")]
        t_cliff = time.time()
        pub.publish(vector_message(types, cliff, stamp, "base_link"))
        r = probe.wait_for(
            lambda: next((r for r in probe.results if r["goal"] == "room17"), None),
            10.0,
            "the result",
            procs,
        )
        assert r["code"] == "BASE_FAULT", r
        assert "cliff front left at (" in r["message"], r
        time.sleep(0.3)
        with probe.lock:
            sent = zip(probe.cmd, probe.cmd_dds, strict=True)
            late = [src - t_cliff for (_, v, w), (src, _) in sent if src > t_cliff and (v or w)]
        # stopped as the message arrived (a heartbeat may have gone out meanwhile)
        assert max(late, default=0.0) < 0.2, late
        print(f"cliff: {r['message']}; motion commands after it: {late}")
    finally:
        for p in procs:
            p.stop()
