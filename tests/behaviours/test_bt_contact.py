"""A drive that touches something (a low box the camera, 1.6 m up, cannot see near the
body): one contact, backed off from and gone round, in the pybullet world of
fig2_hospital (the corridor at x = 0 runs along y, 2 m wide)."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.motion import MAX_CONTACTS, Approach
from pmnav_bt.failures import FailureCode
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D

pytestmark = pytest.mark.world

SOUTH = math.radians(-90)
BOX = (0.3, 25.0)  # east of the centre line: its corner on the robot's left going south
BOX_SIZE, BOX_HEIGHT = 0.4, 0.4  # out of the camera's view within 2.9 m


def room4_step(rig):
    step = rig.plan("0,29,-90", "room3").steps[0]
    assert (step.landmark, step.position) == ("room4", (0.0, 22.0))
    return step


def kinds(rig) -> list[str]:
    return [e.kind for e in rig.ctx.trace]


# where the body, on the centre line, touches the box's corner (0.1, 25.2)
AGAINST_Y = BOX[1] + BOX_SIZE / 2 + math.sqrt(CREATE3_RADIUS_M**2 - 0.1**2) + 1e-3


@pytest.mark.parametrize("start_y", [26.0, AGAINST_Y])
def test_a_touch_is_backed_off_from_and_gone_round(make_rig, start_y):
    """Driving into the unseen box, or starting against it: the body touches it once,
    backs off, steps aside to the open side (west) and arrives. Before, every tick in
    contact counted, and a drive starting against it failed at once. Put down against
    it, the body has driven no floor it could reverse over (the Create 3's backup
    buffer): it steps aside without backing off."""
    rig = make_rig(Pose2D(0.0, start_y, SOUTH))
    rig.add_obstacle(*BOX, size=BOX_SIZE, height=BOX_HEIGHT)
    rig.set(target=room4_step(rig))
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=900)
    rig.expect(seen, Status.SUCCESS)
    assert rig.body.stats.collisions == 1
    assert kinds(rig).count("contact") == 1
    backed = next(e for e in rig.ctx.trace if e.kind == "backed_off")
    if start_y == 26.0:
        assert backed.data["moved"] > 0.1  # it reversed off the box
    else:
        assert backed.data["moved"] < 0.01
        assert backed.data["why"] == "the body would reverse no further"
    assert backed.data["round"][0] < -0.3  # and stepped aside to the west
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (0.0, 22.0)) < 0.2


def test_a_way_touched_shut_fails_blocked_after_each_touch_is_backed_off(make_rig):
    """A low barrier across the corridor: each touch is one contact, backed off from,
    and the drive gives up on the ``MAX_CONTACTS``-th, not after as many ticks."""
    rig = make_rig(Pose2D(0.0, 26.0, SOUTH))
    rig.add_obstacle(0.0, 24.0, size=1.98, height=BOX_HEIGHT)  # y 23.0-25.0, 0.2 m off the walls
    rig.set(target=room4_step(rig))
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=1500)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.BLOCKED
    assert rig.failure.message.startswith(f"{MAX_CONTACTS} collisions on the way: bumped")
    assert kinds(rig).count("contact") == MAX_CONTACTS
    assert kinds(rig).count("backed_off") == MAX_CONTACTS - 1
    assert rig.body.stats.collisions <= MAX_CONTACTS  # no touch the drive did not count
    assert rig.stopped()
