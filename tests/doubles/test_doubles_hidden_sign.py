"""A sign not found with something standing before it is looked for again later (once a
target), not taken for absent; with nothing before it, the search moves on as before."""

from __future__ import annotations

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.hidden_sign import LOOKS_AGAIN, SignHidden
from pmnav_bt.geometry import heading
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.planning.resolve import entity_position, step_entity
from pmnav_bt.seams import Pose2D, View
from pmnav_bt.testing.doubles import FakeObstacle

START = (7.5, 0.0)  # straight_office, on the centre line 2.5 m before room2


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


def looking_at_room2(make_rig, standing: bool):
    """A rig facing room2's sign from START, its view taken, someone standing 40 % of the way
    to the sign or nobody."""
    rig = make_rig(Pose2D(*START, 0.0))
    step = next(s for s in rig.plan("4,0,0", "room3").steps if s.look_for == "room2")
    sign = entity_position(rig.pm, step_entity(rig.pm.building, "room2"))
    rig.body.set_pose(Pose2D(*START, heading(START, sign)))
    mid = (START[0] + 0.4 * (sign[0] - START[0]), START[1] + 0.4 * (sign[1] - START[1]))
    rig.body.obstacles = [FakeObstacle.standing(*mid)] if standing else []
    rig.set(target=step, views=[View(0.0, rig.body.observe())])
    return rig, step


def test_a_sign_with_someone_before_it_is_looked_for_again_once(make_rig):
    rig, step = looking_at_room2(make_rig, standing=True)
    hidden = SignHidden("SignHidden", rig.ctx)
    for _ in range(LOOKS_AGAIN):
        assert rig.run(hidden, max_ticks=1) == [Status.SUCCESS]
    assert rig.run(hidden, max_ticks=1) == [Status.FAILURE]  # then it moves on
    (e,) = [e for e in rig.ctx.trace if e.kind == "sign_hidden"]
    assert e.label == step.landmark and e.data["before_m"] < e.data["sign_m"] - 1.0


def test_a_sign_with_nothing_before_it_is_not_hidden(make_rig):
    rig, _ = looking_at_room2(make_rig, standing=False)
    rig.body.obstacles = [FakeObstacle.standing(0.0, -30.0)]  # depth, nothing in the way
    rig.set(views=[View(0.0, rig.body.observe())])
    assert rig.run(SignHidden("SignHidden", rig.ctx), max_ticks=1) == [Status.FAILURE]
