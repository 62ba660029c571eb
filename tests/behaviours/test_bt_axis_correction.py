"""A drive's wall correction (``behaviours.pose``): worked out in the worker beside the
wall's measurement, taken in the tick only when the estimate is still the one it was
worked out on; otherwise worked out again there, as it always was."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.behaviours.pose import (
    AxisCorrection,
    CorrectHeading,
    axis_correction,
    keep_on_axis,
)
from pmnav_bt.pose.walls import WallLine
from pmnav_bt.seams import Pose2D


def test_a_correction_is_taken_only_on_the_estimate_it_was_worked_out_on(make_rig):
    rig = make_rig(Pose2D(0.0, 0.0, 0.0))
    pm = rig.ctx.pm
    seg = max(pm.segments, key=lambda s: s.length)
    a, b = pm.node_xy(seg.a), pm.node_xy(seg.b)
    mid = (a + b) / 2.0
    odom = Pose2D(float(mid[0]), float(mid[1]), seg.heading + 0.05)  # 3 deg off the axis
    wall = WallLine(-0.05, seg.width / 2.0 - 0.3, 200, 4.0)  # on the left, 0.3 m too near
    tf = (0.0, 0.0, 0.0)
    leaf = CorrectHeading("Leaf", rig.ctx)
    worked = axis_correction(pm, tf, odom, wall)
    assert worked.after is not None and worked.after != tf
    for given in (worked, AxisCorrection((1.0, 2.0, 0.3), (5.0, 5.0, 1.0), "stale")):
        rig.set(map_T_odom=tf, pose_tracker=None)
        assert keep_on_axis(leaf, odom, wall, given) == worked.words
        assert rig.get("map_T_odom") == worked.after
    rig.set(map_T_odom=tf, pose_tracker=None)
    across = WallLine(math.pi / 2.0, 1.0, 200, 4.0)  # a wall across the way: not the corridor's
    assert keep_on_axis(leaf, odom, across, axis_correction(pm, tf, odom, across)) is None
    assert rig.get("map_T_odom") == tf


def _one_corridor(width: float):
    from pmnav_bt.map.building import building_from_data

    return building_from_data(
        {
            "schema_version": 1,
            "name": "one",
            "waypoints": [
                {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
                {"id": "end1", "kind": "end", "pos": [20.0, 0.0]},
            ],
            "edges": [{"from": "start", "to": "end1", "width": width}],
        }
    )


def test_with_a_grid_the_wall_seen_is_placed_where_the_grid_has_it_not_at_half_the_width():
    # The file says 1.2 m wide; the grid (the real walls) 3 m. The robot stands 0.6 m
    # left of the centre line, estimated there, and sees the left wall where the grid has
    # it, about 0.85 m away. Against the rectangle that wall is 0.6 m from the line: the
    # estimate is pulled over 0.4 m towards the right wall (half the 0.85 m it makes of
    # it). Against the grid it stays; an estimate 0.4 m off moves half way to the truth.
    from pmnav_bt.map.floorplan import rasterize_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.pose.evidence.likelihood_field import LikelihoodField

    pm = parse_building(_one_corridor(1.2))
    grid = LikelihoodField.of(rasterize_building(_one_corridor(3.0)))
    truth = np.array([[10.0, 0.6]])
    seen, _ = grid.march(truth, np.array([[0.0, 1.0]]), 5.0)
    wall = WallLine(0.0, float(seen[0]), 200, 4.0)  # along the way, on the left
    odom = Pose2D(10.0, 0.6, 0.0)
    tf = (0.0, 0.0, 0.0)
    pulled = axis_correction(pm, tf, odom, wall).after
    assert pulled is not None and pulled[1] < -0.4
    kept = axis_correction(pm, tf, odom, wall, grid).after
    assert kept is not None and kept[1] == pytest.approx(0.0, abs=0.05)
    off = axis_correction(pm, (0.0, -0.4, 0.0), odom, wall, grid).after
    assert off[1] == pytest.approx(-0.2, abs=0.05)
    # A wall seen where the grid has none within a metre (a doorway, another wall): none.
    far = WallLine(0.0, float(seen[0]) + 1.5, 200, 4.0)
    assert axis_correction(pm, tf, odom, far, grid).after is None
