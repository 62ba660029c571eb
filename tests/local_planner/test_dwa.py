"""The dynamic window: within the body's limits and accelerations, never onto a lethal
cell, round what stands on the way, and no way where the navigation function finds none."""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.local_planner.costmap import LocalCostmap
from pmnav_bt.local_planner.dwa import Dynamics, choose, navigation, rollout, window

DYN = Dynamics()


def wall(x: float, y0: float, y1: float) -> np.ndarray:
    ys = np.arange(y0, y1, 0.02)
    return np.column_stack((np.full_like(ys, x), ys))


def test_the_window_keeps_the_limits_and_the_accelerations():
    for v0, w0 in [(0.0, 0.0), (0.3, 1.8), (0.1, -1.9)]:
        v, w = window(v0, w0, DYN)
        assert (v >= 0.0).all() and (v <= DYN.max_linear).all()
        assert (np.abs(w) <= DYN.max_angular).all()
        assert (np.abs(v - v0) <= DYN.accel_linear * DYN.period + 1e-9).all()
        assert (np.abs(w - w0) <= DYN.accel_angular * DYN.period + 1e-9).all()


def test_straight_at_a_goal_on_open_floor():
    grid = LocalCostmap().snapshot()
    c = choose(grid, None, (0.0, 0.0, 0.0), (0.3, 0.0), (2.0, 0.0), None, DYN)
    assert c.v == DYN.max_linear and abs(c.w) < 0.2


def test_it_turns_away_from_a_box_ahead_and_never_onto_a_lethal_cell():
    cm = LocalCostmap()
    cm.mark(wall(0.6, -0.3, 0.3), now=0.0)
    grid = cm.snapshot()
    nav = navigation(grid, 0.0, 0.0, (2.0, 0.0))
    c = choose(grid, nav, (0.0, 0.0, 0.0), (0.3, 0.0), (2.0, 0.0), None, DYN)
    assert abs(c.w) > 0.1  # going round
    px, py, _ = rollout(0.0, 0.0, 0.0, np.array([c.v]), np.array([c.w]))
    assert (grid.clearance(px, py) >= grid.lethal_m).all()


def test_no_way_through_a_wall_across_the_window_but_round_a_gap_in_it():
    """The navigation function is the drive's answer to "is the way shut" (it holds)."""
    here = np.array([0.0]), np.array([0.0])
    cm = LocalCostmap()
    cm.mark(wall(0.8, -5.5, 5.5), now=0.0)
    nav = navigation(cm.snapshot(), 0.0, 0.0, (2.0, 0.0))
    assert not math.isfinite(float(nav.at(*here)[0]))
    cm = LocalCostmap()
    cm.mark(np.vstack((wall(0.8, -5.5, 0.8), wall(0.8, 1.4, 5.5))), now=0.0)  # a 0.6 m gap
    nav = navigation(cm.snapshot(), 0.0, 0.0, (2.0, 0.0))
    # by the gap at (0.8, 1.1): 1.4 + 1.6 m, less the goal seed 0.3 (straight: 1.7 m)
    assert float(nav.at(*here)[0]) > 2.4
