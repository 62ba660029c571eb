"""Clutter seen from afar and then lost from view is driven round, not touched: every
frame the body takes goes into the drives' local costmap, and the direct drive keeps its
footprint clear of what it holds (``local_planner/clear_way.py``). The pybullet world of
fig2_hospital: the corridor at x = 0 runs along y, 2 m wide."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.belief import DriveEnd
from pmnav_bt.behaviours.follow_lead import CorridorDrive, DriveAlongCorridor
from pmnav_bt.behaviours.motion import Approach
from pmnav_bt.seams import Pose2D

pytestmark = pytest.mark.world

SOUTH = math.radians(-90)
BOX = (0.3, 25.0)  # east of the centre line: the body going south would brush its corner
BOX_SIZE, BOX_HEIGHT = 0.4, 0.4  # out of the camera's view within 2.9 m


def room4_step(rig):
    step = rig.plan("0,29.5,-90", "room3").steps[0]
    assert (step.landmark, step.position) == ("room4", (0.0, 22.0))
    return step


def test_a_box_seen_from_afar_is_driven_round_without_a_touch(make_rig):
    """From 4.3 m the camera sees the low box; from 2.9 m on it no longer does. The drive
    goes round it on the open side (west) and arrives: no contact. Before, the direct
    drive went straight on and touched it (``test_bt_contact``: then backed off)."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    rig.add_obstacle(*BOX, size=BOX_SIZE, height=BOX_HEIGHT)
    rig.set(target=room4_step(rig))
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=900)
    rig.expect(seen, Status.SUCCESS)
    assert rig.body.stats.collisions == 0
    assert [e for e in rig.ctx.trace if e.kind == "contact"] == []
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (0.0, 22.0)) < 0.2


def test_a_look_marks_the_costmap(make_rig):
    """A frame taken for anything (a panorama's view, a look) marks what it shows in the
    drives' costmap: the box 4.3 m ahead is there before any drive starts."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    rig.add_obstacle(*BOX, size=BOX_SIZE, height=BOX_HEIGHT)
    assert rig.ctx.steering.clearance(*BOX) == math.inf
    rig.ctx.base.observe()
    assert rig.ctx.steering.clearance(BOX[0], BOX[1] + 0.2) < 0.1


def test_the_localization_drive_goes_round_a_box_seen_from_afar(make_rig, monkeypatch):
    """The drive along the corridor (``follow_lead``) steers by the walls and goes round
    what the costmap holds on its way: the low box seen 4.3 m ahead, below the view from
    2.9 m on, is passed without a touch. Before, it drove along its heading into it."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    rig.add_obstacle(*BOX, size=BOX_SIZE, height=BOX_HEIGHT)
    monkeypatch.setattr(rig.ctx.grounder, "read_signs", lambda obs: [])  # no sign stop
    drive = CorridorDrive((0.0, 29.5), 6.0, SOUTH, 5.5, last_ray=(0.0, 29.5))
    rig.set(belief=None, corridor_drive=drive, drive_end=None)
    seen = rig.run(DriveAlongCorridor("Drive", rig.ctx), max_ticks=600)
    rig.expect(seen, Status.SUCCESS)
    assert rig.get("drive_end") == DriveEnd.COVERED
    assert rig.body.stats.collisions == 0
    assert rig.true_pose().y < 24.5  # past the box


def test_a_goal_with_a_box_on_it_is_reached_short_of_the_box(make_rig):
    """A box stands where the drive's goal is (the corridor's node abeam room4): the drive
    stops short of it, as near as the body may stand, instead of pushing into it."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    rig.add_obstacle(0.0, 21.9, size=0.4, height=1.0)
    rig.set(target=room4_step(rig))
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=900)
    rig.expect(seen, Status.SUCCESS)
    assert rig.body.stats.collisions == 0
    assert "stopped_short" in [e.kind for e in rig.ctx.trace]
    assert 22.1 + 0.17 < rig.true_pose().y < 22.1 + 0.17 + 0.4
