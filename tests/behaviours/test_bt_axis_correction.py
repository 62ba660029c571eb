"""A drive's wall correction (``behaviours.pose``): worked out in the worker beside the
wall's measurement, taken in the tick only when the estimate is still the one it was
worked out on; otherwise worked out again there, as it always was."""

from __future__ import annotations

import math

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
