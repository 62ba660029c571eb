"""The straight way judged against the costmap, and the way round what it marks."""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.local_planner.clear_way import blocked_at, point_round
from pmnav_bt.local_planner.costmap import LocalCostmap


def disc(cx: float, cy: float, r: float) -> list[tuple[float, float]]:
    pts = []
    for x in np.arange(cx - r, cx + r + 1e-9, 0.05):
        for y in np.arange(cy - r, cy + r + 1e-9, 0.05):
            if math.hypot(x - cx, y - cy) <= r:
                pts.append((float(x), float(y)))
    return pts


def test_a_mark_beside_the_line_blocks_it_where_the_body_would_brush_it():
    """A box 0.3 m off the line (its edge 0.15 m off, inside the body's 0.17 m radius):
    the way is blocked before the box, not at the start; the same box 0.6 m off leaves it
    clear."""
    cm = LocalCostmap()
    cm.mark(disc(2.0, 0.3, 0.15), now=0.0)
    grid = cm.snapshot()
    s = blocked_at(grid, (0.0, 0.0), (4.0, 0.0))
    assert s is not None and 1.5 < s < 2.0
    cm = LocalCostmap()
    cm.mark(disc(2.0, 0.6, 0.15), now=0.0)
    assert blocked_at(cm.snapshot(), (0.0, 0.0), (4.0, 0.0)) is None


def test_the_way_round_keeps_the_body_clear_and_leaves_on_the_open_side():
    """A box on the line and a wall 0.8 m to its left (+y): the point round it lies on the
    right, and the straight ways to it and from it on to the goal keep the lethal
    distance."""
    cm = LocalCostmap()
    wall = [(float(x), 0.8) for x in np.arange(-1.0, 5.0, 0.05)]
    cm.mark(disc(2.0, 0.1, 0.2) + wall, now=0.0)
    grid = cm.snapshot()
    via = point_round(grid, (0.0, 0.0), (4.0, 0.0))
    assert via is not None
    assert via[1] < -0.2  # the right, away from the wall
    assert blocked_at(grid, (0.0, 0.0), via) is None


def test_no_way_round_a_way_marked_shut():
    cm = LocalCostmap()
    cm.mark([(2.0, float(y)) for y in np.arange(-5.0, 5.0, 0.05)], now=0.0)  # wall to wall
    assert point_round(cm.snapshot(), (0.0, 0.0), (4.0, 0.0)) is None


def test_standing_beside_a_mark_the_way_off_it_is_open():
    """The body within the lethal distance of what it touched, behind it: driving away is
    not blocked; driving into it is."""
    cm = LocalCostmap()
    cm.mark(disc(0.45, 0.0, 0.25), now=0.0)  # its near face 0.2 m ahead of the centre
    grid = cm.snapshot()
    assert blocked_at(grid, (0.0, 0.0), (-2.0, 0.0)) is None
    s = blocked_at(grid, (0.0, 0.0), (2.0, 0.0))
    assert s is not None and s < 0.1
