"""The mission across levels on the doubles: localize on L1 of the two-level hospital,
walk to the lift, ride it to L2 and walk on to a room there (issue 40)."""

from __future__ import annotations

import math

import py_trees
import pytest

from pmnav_bt.backends import Backends
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.site import load_site
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.planning.site_plan import SitePlanner
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import (
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.fake_lift import FakeLift
from pmnav_bt.trees.lift import level_context
from pmnav_bt.trees.runner import run_tree
from pmnav_bt.trees.site import build_site_tree

START = Pose2D(3.0, 0.0, 0.0)  # L1's main corridor, by the entrance, facing east
MAX_TICKS = 30_000


@pytest.fixture(scope="module")
def sm():
    return parse_site(load_site("hospital_2l"))


@pytest.fixture(scope="module")
def building(sm):
    return sm.site.level("L1").building


def mission(make_rig, sm, goal: str, overrides=(), session="/robot1/pmnav", **lift):
    """The rig on L1, each level's context, the site plan to ``goal`` and the FakeLift of
    its first ride (``lift``: its script); the tree asks for lifts by ``session``."""
    rig = make_rig(START, overrides=overrides)
    plan = SitePlanner().plan(sm, "L1", START, goal)
    contexts = {"L1": rig.ctx}
    for name, pm in sm.maps.items():
        if name != "L1":
            backends = Backends(
                ScriptedGrounder(pm), FakeCoarseDirection(), FakeRefiner(), FakePlanner()
            )
            contexts[name] = level_context(rig.ctx, pm, backends=backends)
    ride = plan.rides[0]
    fake = FakeLift(rig.base.clock, levels=("L1", "L2"), name=ride.lift, **lift)
    return rig, plan, fake, lambda ctx, goal: build_site_tree(
        contexts, sm, plan, fake, session=session
    )


def test_a_mission_across_levels_reaches_the_room_on_the_other_level(make_rig, sm):
    rig, plan, lift, build = mission(make_rig, sm, "Laboratory")
    assert plan.goal_level == "L2" and plan.goal == "room208" and len(plan.rides) == 1
    levels = []  # the blackboard's level after each tick: the action's feedback reports it

    def level(tree) -> None:
        levels.append(py_trees.blackboard.Blackboard.storage.get("/pmnav/level"))

    out = run_tree(rig.ctx, plan.goal, max_ticks=MAX_TICKS, build=build, on_tick=level)
    assert out.success, out.failure
    assert [r[1:] for r in lift.requests] == [("L1", "/robot1/pmnav"), ("L2", "/robot1/pmnav")]
    assert [t for t, _ in lift.releases] and {s for _, s in lift.releases} == {"/robot1/pmnav"}
    assert levels[0] == "L1" and levels[-1] == "L2"
    assert [lv for i, lv in enumerate(levels) if i == 0 or lv != levels[i - 1]] == ["L1", "L2"]
    door = sm.maps["L2"].building.room("room208").door
    p = rig.true_pose()
    assert math.dist((p.x, p.y), door) < 1.0
    goals = [e.label for e in rig.ctx.trace if e.kind == "plan"]
    lobby = sm.site.lift(plan.rides[0].lift).lobbies["L1"]
    assert goals[0] == lobby and goals[-1] == "room208"  # the lift's lobby, then the room
    kinds = [e.kind for e in rig.ctx.trace]
    assert kinds.index("level") < len(kinds) - 1 - kinds[::-1].index("plan")


def test_a_lift_that_never_comes_ends_the_mission_with_lift_not_coming(make_rig, sm):
    rig, plan, _, build = mission(
        make_rig, sm, "Laboratory", overrides=("tree.lift_wait_s=20",), never=True
    )
    out = run_tree(rig.ctx, plan.goal, max_ticks=MAX_TICKS, build=build)
    assert not out.success and out.failure.code == FailureCode.LIFT_NOT_COMING
