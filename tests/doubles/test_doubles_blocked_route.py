"""A whole mission on the doubles round a ring of corridors: a corridor that stays shut
is marked blocked for the run and the plan goes round it after exactly one replan,
never coming back to it; with no way round, the run ends naming what shut it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from building_kit import with_landmark
from rig import build_rig

from pmnav_bt.failures import FailureCode
from pmnav_bt.map.building import Landmark
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import FakeObstacle

START = Pose2D(25.0, -11.0, math.radians(90.0))  # loop_hospital: the stem up to branch1
BARRIER_X = 27.0  # across seg4 (branch1-room4), east of branch1 on the ring
MAX_TICKS = 40_000


@pytest.fixture(scope="module")
def building():
    return load_building("loop_hospital")


def barrier(x: float, half_width: float = 1.4):
    """Standing cylinders across the ring's corridor at ``x`` (y = 0), edge to edge."""
    n = int(2 * half_width / 0.2) + 1
    return [FakeObstacle.standing(x, -half_width + 0.2 * i, 0.12) for i in range(n)]


def distance_to_path(path, point) -> float:
    pts = np.asarray(path, float)
    best = math.inf
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        d = b - a
        t = 0.0 if not d.any() else float(np.clip((point - a) @ d / (d @ d), 0.0, 1.0))
        best = min(best, float(np.linalg.norm(a + t * d - point)))
    return best


def test_a_corridor_that_stays_shut_is_gone_round_after_one_replan(make_rig):
    rig = make_rig(START, budget=5000)  # the way round the ring is 130 m
    rig.body.obstacles = barrier(BARRIER_X)
    out = rig.mission("room8", max_ticks=MAX_TICKS)
    assert out.success, out.failure
    assert out.replans == 1
    trace = rig.ctx.trace
    (marked,) = [e for e in trace if e.kind == "blocked"]
    assert marked.label == "the corridor between branch1 and room4"
    plans = [e for e in trace if e.kind == "plan"]
    assert len(plans) == 2
    at = np.array([BARRIER_X, 0.0])
    assert distance_to_path(plans[0].data["path"], at) < 0.5  # the first went through it
    assert distance_to_path(plans[1].data["path"][1:], at) >= 2.0  # back by branch1, round
    # no oscillation: after the replan the robot never came back to the barrier
    stops = [e for e in trace if e.kind == "obstacle"]
    assert stops and all(e.time < marked.time for e in stops)
    p = rig.true_pose()
    assert rig.body.gap() > 0.0 and math.dist((p.x, p.y), (BARRIER_X, 0.0)) > 5.0


def test_a_closed_fire_door_with_no_way_round_ends_the_run_naming_it(building, clean_blackboard):
    # the ring shut on both sides of branch1 (a closed fire door, a barrier): no way round
    door = Landmark(id="fd_east", kind="fire_door", name="FD-E", pos=(BARRIER_X, 0.0))
    fire = parse_building(with_landmark(building, door))
    rig = build_rig("doubles", fire, START, overrides=("tree.replans=2",))
    try:
        rig.body.obstacles = barrier(BARRIER_X) + barrier(22.0)
        out = rig.mission("room8", max_ticks=MAX_TICKS)
    finally:
        rig.close()
    assert not out.success
    f = out.failure
    assert f.code == FailureCode.DOOR_CLOSED, f
    assert f.message.startswith("no way round: "), f.message
    assert "fire door FD-E at fd_east closed" in f.message, f.message
    assert "the corridor between room39 and branch1 blocked for" in f.message, f.message
