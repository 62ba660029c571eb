"""The map-less baseline's own record: the occupancy grid, frontiers, and the choice."""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.perception.scan import Scan
from pmnav_bt.planning.frontier import FREE, OCCUPIED, UNKNOWN, ExplorationGrid


def corridor_grid(visited_left: bool) -> ExplorationGrid:
    """A corridor along x (2.4 m wide) seen from x = -3 to x = +4, unknown beyond both
    ends: two frontiers, the left one nearer the robot at the origin."""
    g = ExplorationGrid(half_extent=20.0)
    for x in np.arange(-3.0, 4.0, 0.1):
        for y in np.arange(-1.1, 1.1, 0.1):
            r, c = g.to_cell(x, y)
            g.state[r, c] = FREE
        for y in (-1.3, 1.3):
            r, c = g.to_cell(x, y)
            g.state[r, c] = OCCUPIED
    if visited_left:
        for x in np.arange(-3.0, 0.0, 0.25):
            g.mark_visited(x, 0.0)
    return g


def test_an_unexplored_branch_beats_a_nearer_visited_one():
    # Facing left (yaw pi), the left frontier is nearer and ahead; the robot has been there.
    pose = (0.0, 0.0, math.pi)
    fresh = corridor_grid(visited_left=False).choose(pose)
    assert fresh is not None and fresh.target[0] < -2.5  # nothing known: the nearer one
    been = corridor_grid(visited_left=True).choose(pose)
    assert been is not None and been.target[0] > 3.5  # the branch not yet driven down
    assert math.dist(been.path[-1], been.target) < 1.1  # the path ends by the frontier


def test_a_frontier_driven_to_is_not_chosen_again():
    g = corridor_grid(visited_left=False)
    first = g.choose((0.0, 0.0, math.pi))
    g.mark_spent(first.target)
    second = g.choose((0.0, 0.0, math.pi))
    assert second is not None and second.target[0] > 3.5
    g.mark_spent(second.target)
    assert g.choose((0.0, 0.0, 0.0)) is None  # everything reachable seen


def test_a_scan_frees_its_rays_and_marks_what_they_hit():
    g = ExplorationGrid(half_extent=20.0)
    bearings = np.radians(np.arange(-30.0, 30.5, 1.0))
    # a wall 3 m ahead, except a gap straight ahead that goes on beyond the range
    ranges = np.where(np.abs(bearings) < np.radians(5), np.inf, 3.0 / np.cos(bearings))
    g.integrate(Scan(bearings, ranges, 6.0, (0.0, 0.0, 0.0)))
    at = lambda x, y: g.state[g.to_cell(x, y)]  # noqa: E731
    assert at(1.5, 0.5) == FREE and at(3.05, 1.0) == OCCUPIED
    assert at(5.0, 0.0) == FREE and at(6.5, 0.0) == UNKNOWN  # free to the range, no further
    assert at(4.0, 1.5) == UNKNOWN  # behind the wall
    assert g.frontier_mask()[g.to_cell(5.9, 0.0)]  # the gap goes on: a frontier


def test_forgetting_keeps_where_the_robot_has_been():
    g = corridor_grid(visited_left=True)
    g.mark_spent((4.0, 0.0))
    g.forget()
    assert (g.state == UNKNOWN).all() and g.spent == [] and g.visited.any()
    assert g.choose((0.0, 0.0, 0.0)) is None  # nothing seen: look around first


def test_a_wall_drawn_by_drift_is_cleared_by_later_looks_through_it():
    g = ExplorationGrid(half_extent=20.0)
    one = np.zeros(1)
    g.integrate(Scan(one, np.array([2.0]), 6.0, (0.0, 0.0, 0.0)))  # a wall 2 m ahead
    assert g.state[g.to_cell(2.0, 0.0)] == OCCUPIED
    clear = Scan(one, np.array([np.inf]), 6.0, (0.0, 0.0, 0.0))
    g.integrate(clear)
    assert g.state[g.to_cell(2.0, 0.0)] == OCCUPIED  # one look through is not enough
    g.integrate(clear)
    g.integrate(clear)
    assert g.state[g.to_cell(2.0, 0.0)] == FREE
