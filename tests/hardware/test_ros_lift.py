"""Lifts over DDS: the lift client (``RosLiftClient``, this process) and the simulated lift
node (``pmnav-sim-lift``, another process) speak Open-RMF's lift protocol on
/lift_requests and /lift_states in a private domain.

One robot calls the lift to its level, sees the door open there, rides to another level
and releases the lift; a second robot that asked for the lift meanwhile is not answered
while the first holds it, and gets it once the first has released it (its client asks
again on each state, as RMF's lift supervisor does).
"""

from __future__ import annotations

import time

import pytest

from pmnav_bt.hardware import rmf_lift
from pmnav_bt.hardware.testing import Proc
from pmnav_bt.seams import LiftDoor, LiftMotion

pytestmark = [
    pytest.mark.timeout(120),
    pytest.mark.skipif(not rmf_lift.available(), reason="rmf_lift_msgs not built"),
]
LIFT = "lift1"
# fast, so the test stays short: a ride of 1 s a level, doors of 0.5 s, calls within 1 s
TIMING = dict(ride_s_per_level=1.0, door_s=0.5, dwell_s=0.5, call_delay_s=1.0)
WAIT_S = 20.0  # for any one thing the lift should do (a loaded machine is slow)


@pytest.fixture
def lifts(domain_id, tmp_path):
    """The simulated lift node, and two robots' lift clients in this process."""
    from rclpy.node import Node

    from pmnav_bt.hardware.lift_client import RosLiftClient
    from pmnav_bt.hardware.runtime import RosRuntime

    sim = Proc(
        "pmnav_bt.hardware.sim_lift_node",
        dict(lifts=f"{LIFT},lift2", levels="L1,L2,L3", start_level="L2", seed=1, **TIMING),
        domain_id,
        tmp_path / "sim_lift.log",
    )
    rt = RosRuntime(args=[], domain_id=domain_id)
    clients = []
    for name in ("robot_a", "robot_b"):
        node = Node(name, context=rt.context)
        clients.append(RosLiftClient(node))
        rt.add(node)
    rt.start()
    try:
        yield sim, clients
    finally:
        rt.shutdown()
        assert sim.stop() == 0, sim.tail()


def wait_state(client, sim, pred, what: str, seen: list | None = None):
    """The lift's state once ``pred(state)`` holds (states polled meanwhile go to ``seen``)."""
    deadline = time.monotonic() + WAIT_S
    while True:
        s = client.state(LIFT)
        if s is not None:
            if seen is not None and (not seen or seen[-1] != s):
                seen.append(s)
            if pred(s):
                return s
        if time.monotonic() > deadline or not sim.alive():
            raise AssertionError(f"waiting for {what}; last state {s}\n{sim.tail()}")
        time.sleep(0.05)


def test_ride_and_session_conflict_over_dds(lifts):
    sim, (a, b) = lifts
    s = wait_state(a, sim, lambda s: True, "the first LiftState")
    assert (s.current_level, s.session) == ("L2", "")
    assert s.available_levels == ("L1", "L2", "L3")

    # robot A calls the lift down to its level: the cabin comes, the door opens for A
    a.request(LIFT, "L1", "robot_a")
    seen: list = []
    s = wait_state(a, sim, lambda s: s.door == LiftDoor.OPEN, "the door open at L1", seen)
    assert (s.current_level, s.session, s.motion) == ("L1", "robot_a", LiftMotion.STOPPED)
    assert LiftMotion.DOWN in {x.motion for x in seen}

    # robot B asks for the lift while A holds it: not answered
    b.request(LIFT, "L3", "robot_b")
    wait_state(b, sim, lambda s: s.session == "robot_a", "B hearing that A holds the lift")

    # A rides to L3: the door closes, the cabin goes up, the door opens there, still A's
    a.request(LIFT, "L3", "robot_a")
    seen = []
    s = wait_state(
        a, sim, lambda s: s.current_level == "L3" and s.door == LiftDoor.OPEN,
        "the door open at L3", seen,
    )  # fmt: skip
    assert s.session == "robot_a"
    assert LiftMotion.UP in {x.motion for x in seen}
    assert all(x.door == LiftDoor.CLOSED for x in seen if x.motion == LiftMotion.UP)
    assert b.state(LIFT).session != "robot_b"  # B still waits

    # A releases the lift: B, which kept asking, gets it at L3 with the door open
    a.release(LIFT, "robot_a")
    s = wait_state(
        b, sim, lambda s: s.session == "robot_b" and s.door == LiftDoor.OPEN, "B's session"
    )
    assert (s.current_level, s.destination_level) == ("L3", "L3")
    b.release(LIFT, "robot_b")
    wait_state(b, sim, lambda s: s.session == "", "the lift free again")
    assert a.state("lift2").current_level == "L2"  # the other lift was never called


def test_pmnav_ros_hears_the_lifts_with_the_lifts_parameter(domain_id, tmp_path, probe):
    """``pmnav-ros -p lifts:=true`` runs the lift client: its status says what each lift
    of the simulated two-level hospital said on /lift_states, and ``--record`` keeps those
    states in the run's MCAP file beside the robot's own topics."""
    from mcap_ros2.reader import read_ros2_messages

    record = tmp_path / "run.mcap"
    sim = Proc("pmnav_bt.hardware.sim_lift_node", dict(site="hospital_2l"), domain_id,
               tmp_path / "sim_lift.log")  # fmt: skip
    ctl = Proc("pmnav_bt.hardware.node", {"lifts": True}, domain_id, tmp_path / "pmnav.log",
               options=("--record", str(record)))  # fmt: skip
    try:
        st = probe.wait_for(
            lambda: (probe.status or {}).get("lifts", {}).get(LIFT), 90.0, "lift1 in the status",
            procs=(sim, ctl),
        )  # fmt: skip
        assert st == "at L1, to L1, door closed, stopped, session none"
    finally:
        ctl.stop(timeout=15.0)
        sim.stop()
    states = [m.ros_msg for m in read_ros2_messages(str(record), topics=["/lift_states"])]
    assert {s.lift_name for s in states} >= {"lift1", "lift2"}, ctl.tail()
    assert all(s.current_floor == "L1" for s in states if s.lift_name == LIFT)


def test_states_and_requests_carry_rmf_fields(ros_required):
    """LiftState -> rmf_lift_msgs/LiftState -> LiftState keeps every field; a request is
    AGV mode with the door open, a release REQUEST_END_SESSION."""
    from builtin_interfaces.msg import Time
    from rmf_lift_msgs.msg import LiftRequest

    from pmnav_bt.seams import LiftState

    s = LiftState("lift1", "L2", "L3", LiftDoor.MOVING, LiftMotion.UP, "robot",
                  ("L1", "L2", "L3"), 12.5)  # fmt: skip
    msg = rmf_lift.state_message(s)
    assert (msg.current_floor, msg.door_state, msg.motion_state) == ("L2", 1, 1)
    assert rmf_lift.state_from_message(msg) == s
    req = rmf_lift.request_message("lift1", "L3", "robot", Time(sec=3))
    assert (req.request_type, req.door_state) == (LiftRequest.REQUEST_AGV_MODE, 2)
    end = rmf_lift.request_message("lift1", "L3", "robot", Time(sec=3), end=True)
    assert end.request_type == LiftRequest.REQUEST_END_SESSION and end.session_id == "robot"


@pytest.mark.timeout(300)  # three nodes start, then the robot localizes and drives
def test_pmnav_ros_on_a_site_calls_the_lift_for_a_goal_on_another_level(domain_id, tmp_path):
    """``pmnav-ros -p building:=hospital_2l -p lifts:=true`` (node ``/robot1``) runs a goal on
    L2 as the mission across levels: its feedback names the start level L1, and at the
    lift's lobby it calls the lift by its own name, which the simulated lift node grants
    (the ride itself needs the simulated Create 3 to change levels, which it cannot)."""
    from rclpy.node import Node

    from pmnav_bt.hardware.action_client import ThreadSafeActionClient
    from pmnav_bt.hardware.action_server import action_type
    from pmnav_bt.hardware.lift_client import RosLiftClient
    from pmnav_bt.hardware.runtime import RosRuntime
    from pmnav_bt.map.site import load_site

    if action_type() is None:
        pytest.skip("pmnav_interfaces not built")
    l1 = load_site("hospital_2l").level("L1")
    procs = [
        Proc("pmnav_bt.hardware.sim_lift_node", dict(site="hospital_2l", seed=1, **TIMING),
             domain_id, tmp_path / "sim_lift.log"),
        Proc("pmnav_bt.hardware.sim_create3", dict(building=str(l1.path), width=240, height=180),
             domain_id, tmp_path / "create3.log"),
        Proc("pmnav_bt.hardware.node", dict(building="hospital_2l", lifts=True,
             overrides="grounder.backend=sim_gt"), domain_id, tmp_path / "pmnav.log",
             name="robot1"),
    ]  # fmt: skip
    rt = RosRuntime(args=[], domain_id=domain_id)
    node = Node("site_test", context=rt.context)
    lifts = RosLiftClient(node)  # only listens: what the lifts say
    client = ThreadSafeActionClient(node, action_type(), "navigate_to_room")
    rt.add(node)
    rt.start()
    logs = lambda: "\n".join(f"--- {p.log.name}\n{p.tail()}" for p in procs)  # noqa: E731
    try:
        assert client.wait_for_server(timeout_sec=60.0), logs()
        feedback: list = []
        fut = client.send_goal_async(
            action_type().Goal(room="Laboratory"),
            feedback_callback=lambda m: feedback.append(m.feedback),
        )
        deadline = time.monotonic() + 240.0
        held = None
        while held is None:
            held = next(
                (s for name in ("lift1", "lift2") if (s := lifts.state(name)) is not None
                 and s.session == "/robot1"), None,
            )  # fmt: skip
            dead = [p for p in procs if not p.alive()]
            assert time.monotonic() < deadline and not dead, f"no lift called\n{logs()}"
            time.sleep(0.2)
        assert held.destination_level == "L1"  # called to the robot's level
        levels = {f.level for f in feedback if f.phase != "waiting_for_sensors"}
        assert levels == {"L1"}, levels
        handle = fut.result()
        handle.cancel_goal_async()
    finally:
        rt.shutdown()
        for p in reversed(procs):
            p.stop()
