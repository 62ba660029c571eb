"""The simulated lifts behind ``pmnav-sim-lift`` (hardware/lift_bank.py), on a hand-moved
clock: no ROS needed. A lift serves one session at a time, waits its seeded call delay,
closes its door before it moves, rides a fixed time per level, opens at the destination
and holds the door through the dwell after a release."""

from __future__ import annotations

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware.lift_bank import LiftBank
from pmnav_bt.lift_timing import LiftTiming
from pmnav_bt.seams import Lift, LiftDoor, LiftMotion


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def bank(clock, **kw):
    timing = dict(ride_s_per_level=2.0, door_s=1.0, dwell_s=3.0, call_delay_s=0.0)
    timing |= {k: kw.pop(k) for k in list(kw) if k in timing}
    levels = ["L1", "L2", "L3"]
    return LiftBank(
        {"lift1": levels, "lift2": levels}, clock=clock, timing=LiftTiming(**timing), **kw
    )


def at(clock, b, t, lift="lift1"):
    clock.t = 100.0 + t
    return b.state(lift)


def test_a_call_rides_to_the_level_and_opens_the_door_there():
    clock = Clock()
    b = bank(clock)
    assert isinstance(b, Lift)
    s = b.state("lift1")
    assert (s.current_level, s.door, s.session) == ("L1", LiftDoor.CLOSED, "")
    assert s.available_levels == ("L1", "L2", "L3")
    b.request("lift1", "L3", "robot")
    s = at(clock, b, 0.5)
    assert (s.session, s.destination_level, s.motion) == ("robot", "L3", LiftMotion.UP)
    assert at(clock, b, 2.5).current_level == "L2"  # 1.25 levels up: nearest L2
    s = at(clock, b, 4.5)  # arrived at 4 s; the door is half open
    assert (s.current_level, s.motion, s.door) == ("L3", LiftMotion.STOPPED, LiftDoor.MOVING)
    assert at(clock, b, 5.0).door == LiftDoor.OPEN
    assert b.state("lift2").current_level == "L1"  # the other lift did not move
    assert b.state("lift3") is None


def test_the_door_closes_before_the_cabin_moves():
    clock = Clock()
    b = bank(clock)
    b.request("lift1", "L1", "robot")
    assert at(clock, b, 1.0).door == LiftDoor.OPEN
    b.request("lift1", "L2", "robot")  # the robot is in: ride to L2
    s = at(clock, b, 1.5)
    assert (s.door, s.motion, s.current_level) == (LiftDoor.MOVING, LiftMotion.STOPPED, "L1")
    s = at(clock, b, 2.5)  # closed at 2 s, moving since
    assert (s.door, s.motion) == (LiftDoor.CLOSED, LiftMotion.UP)
    s = at(clock, b, 5.0)  # arrived at 4 s, door open at 5 s
    assert (s.current_level, s.door) == ("L2", LiftDoor.OPEN)


def test_a_lift_in_another_sessions_use_does_not_answer_until_released():
    clock = Clock()
    b = bank(clock)
    b.request("lift1", "L2", "alice")
    b.request("lift1", "L3", "bob")  # refused: alice holds it
    s = at(clock, b, 3.0)
    assert (s.session, s.destination_level, s.current_level) == ("alice", "L2", "L2")
    b.release("lift1", "bob")  # only the holder can end its session
    assert at(clock, b, 3.0).session == "alice"
    b.release("lift1", "alice")
    assert at(clock, b, 3.0).session == ""
    b.request("lift1", "L3", "bob")
    s = at(clock, b, 3.5)
    assert (s.session, s.destination_level) == ("bob", "L3")


def test_the_door_stays_open_through_the_dwell_after_a_release():
    clock = Clock()
    b = bank(clock)
    b.request("lift1", "L1", "robot")
    assert at(clock, b, 1.0).door == LiftDoor.OPEN
    b.release("lift1", "robot")
    assert at(clock, b, 3.9).door == LiftDoor.OPEN  # dwell 3 s: held until 4 s
    assert at(clock, b, 4.5).door == LiftDoor.MOVING
    assert at(clock, b, 5.0).door == LiftDoor.CLOSED


def _start_of_motion(seed: int) -> float:
    clock = Clock()
    b = bank(clock, call_delay_s=10.0, seed=seed)
    b.request("lift1", "L2", "robot")
    for k in range(1, 201):
        if at(clock, b, 0.1 * k).motion == LiftMotion.UP:
            return 0.1 * k
    raise AssertionError("the lift never moved")


def test_call_delays_are_seeded_and_within_the_bound():
    delays = [_start_of_motion(seed) for seed in range(6)]
    assert all(0.0 < d <= 10.1 for d in delays)
    assert len(set(delays)) > 1  # the seed matters
    assert _start_of_motion(3) == delays[3]  # and decides


def test_unknown_levels_and_lifts_are_logged_and_ignored():
    lines = []
    clock = Clock()
    b = bank(clock, log=lines.append)
    b.request("lift1", "L9", "robot")
    b.request("lift7", "L2", "robot")
    assert b.state("lift1").session == ""
    assert any("no level 'L9'" in x for x in lines) and any("no lift 'lift7'" in x for x in lines)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(lifts={"": ["L1"]}), "lift names must not be empty"),
        (dict(lifts={"a": ["L1", "L1"]}), "lift a: level names must be unique and not empty"),
        (dict(lifts={"a": []}), "lift a: level names must be unique and not empty"),
        (dict(lifts={}), "at least one lift"),
        (dict(start_level="L3"), "lift b: start level 'L3' is not one of"),
    ],
)
def test_bad_banks_are_refused_in_one_line(kw, match):
    args = dict(lifts={"a": ["L1", "L2", "L3"], "b": ["L1", "L2"]}) | kw
    with pytest.raises(PmNavError, match=match):
        LiftBank(args.pop("lifts"), **args)


@pytest.mark.parametrize("name", ["ride_s_per_level", "door_s", "dwell_s", "call_delay_s"])
def test_bad_timings_are_refused_in_one_line(name):
    with pytest.raises(PmNavError, match=f"{name} must be 0 or more seconds, not -1.0"):
        LiftTiming(**{name: -1.0})


def test_the_node_takes_a_sites_lifts_or_its_own_list():
    from pmnav_bt.hardware.sim_lift_node import PARAMETERS, bank_lifts

    p = {name: default for name, (default, _) in PARAMETERS.items()}
    assert bank_lifts(p | {"lifts": "a, b", "levels": "G,M"}, set()) == {
        "a": ["G", "M"], "b": ["G", "M"]
    }  # fmt: skip
    site = p | {"site": "hospital_2l"}
    assert bank_lifts(site, {"site"}) == {"lift1": ["L1", "L2"], "lift2": ["L1", "L2"]}
    with pytest.raises(PmNavError, match=r"leave out \['levels'\]"):
        bank_lifts(site, {"site", "levels"})
    with pytest.raises(PmNavError, match="fig2_hospital has no lifts"):
        bank_lifts(p | {"site": "fig2_hospital"}, {"site"})
    with pytest.raises(PmNavError, match="parameter 'lifts': expected comma-separated"):
        bank_lifts(p | {"lifts": " , "}, {"lifts"})
