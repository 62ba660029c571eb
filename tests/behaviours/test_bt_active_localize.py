"""Active localization in a generated sign-sparse building: from a start where no sign is
readable, the localization subtree drives along the corridor axis until it knows where
it is (issue 15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.map.generate import generate_sign_sparse
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D
from pmnav_bt.trees.localize import active_localize_subtree

pytestmark = pytest.mark.world  # a pybullet world: these tests need geometry


@pytest.fixture(scope="module")
def building():  # overrides the fig2_hospital building of conftest
    return generate_sign_sparse(0)


def test_a_start_in_a_sign_less_stretch_localizes_by_driving_along_the_axis(make_rig, pm):
    start = Pose2D(60.0, 45.0, math.radians(90.0))  # a 30 m corridor without a door
    assert Visibility.of(pm).n_readable((start.x, start.y)) == 0
    rig = make_rig(start, width=320, height=240, noise=0.02, seed=3)
    tree = active_localize_subtree(rig.ctx)
    track = []
    seen = rig.run(tree, max_ticks=6000, until=lambda: track.append(rig.true_pose()) and False)
    assert seen[-1].name == "SUCCESS", rig.failure
    assert rig.get("fix_attempts") >= 2  # it had to move
    est, true = rig.estimate(), rig.true_pose()
    assert math.dist((est.x, est.y), (true.x, true.y)) < 1.0
    assert rig.yaw_error(est.yaw, true.yaw) < math.radians(10)
    # It drove along the corridors, never into a wall, and away from the start.
    assert math.dist((true.x, true.y), (start.x, start.y)) > 5.0
    for p in track:
        loc = pm.locate(p.x, p.y)
        assert loc.offset < loc.segment.width / 2, p
    assert rig.body.stats.collisions == 0


def test_the_sign_sparse_building_parses(pm):
    assert pm.building.name == "sign_sparse_0"
    assert parse_building(generate_sign_sparse(0)).segments == pm.segments


def test_before_the_first_glimpse_the_map_says_if_the_views_between_are_worth_a_turn(make_rig, pm):
    """With no belief yet, the share of the map with a sign in reliable reach decides (the
    sign-sparse family: under a third of its corridors), or, when there is one, the last
    estimate: beside a door plate the views between are taken."""
    from py_trees.common import Status

    from pmnav_bt.behaviours.belief import NoSignInReach

    start = Pose2D(60.0, 45.0, math.radians(90.0))
    rig = make_rig(start, overrides=("sim.reading_width=640", "grounder.backend=sim_gt"))
    oracle = NoSignInReach("NoSignInReach", rig.ctx)
    rig.expect(rig.run(oracle), Status.SUCCESS)  # 47 % of the corridors: under half
    vis = Visibility.of(pm)
    near = next(p for p in vis.lattice_points if len(p.readable) >= 2)
    rig.set(map_T_odom=(near.xy[0] - start.x, near.xy[1] - start.y, 0.0))  # "we are there"
    rig.expect(rig.run(NoSignInReach("NoSignInReach", rig.ctx)), Status.FAILURE)


def _bare_far_from_ends(pm, b) -> list[int]:
    """Hypotheses (facing along their corridor) that put the robot on a bare stretch: no
    sign in sight and 9 m or more from any junction or end."""
    vis = Visibility.of(pm)
    ends = np.array([pm.node_xy(n) for n in pm.nodes])
    pts = vis.lattice_points
    return [
        i
        for i in range(len(b.lattice))
        if not pts[b.lattice[i]].readable
        and np.linalg.norm(ends - b.xy[i], axis=1).min() >= 9.0
        and abs(
            math.remainder(b.yaw[i] - pm.segments[pts[b.lattice[i]].segment - 1].heading, math.pi)
        )
        < 0.1
    ]


@pytest.mark.parametrize("drive_end", ["covered", "rethought", "wall ahead", "sign ahead", None])
def test_a_look_round_is_skipped_only_where_it_cannot_tell_and_after_a_plain_drive(
    make_rig, pm, drive_end
):
    """``LookTellsNothing``: with the belief split between two bare stretches (what a look
    shows there is the same), after a drive that covered its lead or turned for another
    way the look is skipped; after one that met a wall or saw a sign ahead, it is taken.
    Either way ``drive_end`` is cleared (one skip per drive). With a third place at a
    junction (its floor looks different), it is taken."""
    from py_trees.common import Status

    from pmnav_bt.behaviours.belief import LookTellsNothing
    from pmnav_bt.pose.belief import CorridorBelief
    from pmnav_bt.pose.glimpse import Glimpse

    start = Pose2D(60.0, 45.0, math.radians(90.0))
    rig = make_rig(start)
    b = CorridorBelief(pm)
    b.observe(Glimpse(start, {}), axis_odom=start.yaw)
    bare = _bare_far_from_ends(pm, b)
    assert len(bare) >= 2
    far = max(bare, key=lambda i: np.linalg.norm(b.xy[i] - b.xy[bare[0]]))
    b.logw[:] = -50.0
    b.logw[[bare[0], far]] = 0.0  # two far-apart bare stretches, equally likely
    rig.set(belief=b, drive_end=drive_end)
    skip = drive_end in ("covered", "rethought")
    look = LookTellsNothing("LookTellsNothing", rig.ctx)
    rig.expect(rig.run(look), Status.SUCCESS if skip else Status.FAILURE)
    assert rig.get("drive_end") is None
    if skip:  # a third place, at a junction: the look can tell it from the others
        junction = next(i for i in range(len(b.lattice)) if len(b.vis.exits[b.lattice[i]]) >= 3)
        b.logw[junction] = 0.0
        rig.set(drive_end=drive_end)
        rig.expect(rig.run(LookTellsNothing("LookTellsNothing", rig.ctx)), Status.FAILURE)
