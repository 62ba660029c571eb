"""A straight way kept clear of what the local costmap holds, and the way round it.

What it models: a careful driver's glance along the way before each stretch. The
camera, 1.6 m up, sees a box 0.4 m high only from 2.9 m off and a 1 m plant only from
1.45 m: once the robot comes nearer, what it saw is below its view. The local costmap
(``costmap.LocalCostmap``) remembers it; a drive that steers straight at its goal
(``behaviours/motion.py`` ``DriveTo`` with the direct steering, the localization drive
``behaviours/follow_lead.py``) asks here, through ``Steering.way_round``, whether its
body's footprint, swept along the straight way, keeps clear of it:

- ``blocked_at``: metres along the straight way to the first point where the body would
  come within the costmap's lethal distance (its radius and a pad) of something marked;
  None when the way is clear. Where the body already stands that near (beside what it
  touched, or a mark made as it passed), the way is judged from where it leaves that
  nearness: moving off is always allowed.
- ``point_round``: where it is not, a point to drive to first: along the shortest way
  round through cells that keep the lethal distance (the navigation function of
  ``dwa.navigation``, fast marching over the window, unknown floor counted free as
  Nav2's local costmap does), the farthest point of that way, within ``ROUND_REACH_M``,
  to which the straight way from the robot is clear. None when marks cut every way
  round in the window, or the way round leaves the caller's walls (the map's corridors:
  the costmap knows only the walls the camera saw, and unknown floor beyond a wall is
  no way): the caller keeps its own rule for a shut way (the depth check, and a touch
  backed off from).

Cheap enough for the tick (``blocked_at``: a few dozen look-ups); ``point_round`` makes a
navigation function (about 10 ms) and belongs in the worker.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from pmnav_bt.local_planner.costmap import CostGrid
from pmnav_bt.local_planner.dwa import navigation

PROBE_M = 0.05  # a way is sampled this finely (a cell)
# A way round is taken this far at most before the straight way is judged again: the
# window's floor nearer than that was seen, and the robot looks again every second.
ROUND_REACH_M = 2.0
DESCENT_STEP_M = 0.05  # the way round follows the navigation function's slope in these steps
OWN_M = 0.3  # where the body stands, beside a wall, the walls' margin is not asked


def blocked_at(
    grid: CostGrid, start: tuple[float, float], end: tuple[float, float]
) -> float | None:
    """Metres from ``start`` along the straight way to ``end`` (odometry) to the first point
    closer than ``grid.lethal_m`` to anything marked; None when none (see the module)."""
    d = math.dist(start, end)
    n = max(1, int(math.ceil(d / PROBE_M)))
    s = np.linspace(0.0, d, n + 1)
    if d == 0.0:
        return None
    x = start[0] + (end[0] - start[0]) * s / d
    y = start[1] + (end[1] - start[1]) * s / d
    clear = grid.clearance(x, y)
    near = clear < grid.lethal_m
    if not near.any():
        return None
    # Standing within the lethal distance: the way is judged once it is left (or from
    # where the clearance stops growing along it: the way runs on along the mark).
    k = 0
    while k < len(s) and near[k] and (k == 0 or clear[k] > clear[k - 1]):
        k += 1
    hit = np.flatnonzero(near[k:])
    return None if len(hit) == 0 else float(s[k + hit[0]])


Inside = Callable[[tuple[float, float]], bool]  # whether an odometry point is in the walls


def point_round(
    grid: CostGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    inside: Inside | None = None,
) -> tuple[float, float] | None:
    """A point (odometry) to drive to first on the way from ``start`` to ``goal`` round what
    the costmap marks (see the module); None when there is no way round in the window, or
    when the way round leaves what ``inside`` allows (the map's corridors: the costmap
    knows only the walls the camera saw) within ``ROUND_REACH_M``."""
    nav = navigation(grid, start[0], start[1], goal)
    here = float(nav.at(np.array([start[0]]), np.array([start[1]]))[0])
    if not math.isfinite(here):
        return None
    field = nav.field.filled(math.inf)
    r = grid.resolution
    n = field.shape[0]
    p = np.array(start, float)
    best = None
    walked = 0.0
    while walked < ROUND_REACH_M:
        i, j, in_window = grid.cells(np.array([p[0]]), np.array([p[1]]))
        if not in_window[0]:
            break
        i, j = int(i[0]), int(j[0])
        lo_i, hi_i, lo_j, hi_j = max(i - 1, 0), min(i + 2, n), max(j - 1, 0), min(j + 2, n)
        patch = field[lo_i:hi_i, lo_j:hi_j]
        k = np.unravel_index(int(np.argmin(patch)), patch.shape)
        ni, nj = lo_i + k[0], lo_j + k[1]
        if not math.isfinite(patch[k]) or (ni, nj) == (i, j) or patch[k] <= 0.0:
            nxt = np.array(nav.goal, float)  # in the goal's seed: the goal itself
            if blocked_at(grid, start, tuple(nxt)) is None:
                best = (float(nxt[0]), float(nxt[1]))
            break
        nxt = np.array([grid.origin[0] + (nj + 0.5) * r, grid.origin[1] + (ni + 0.5) * r])
        walked += float(np.linalg.norm(nxt - p))
        p = nxt
        if inside is not None and walked > OWN_M and not inside((float(p[0]), float(p[1]))):
            return None
        if blocked_at(grid, start, (float(p[0]), float(p[1]))) is None:
            best = (float(p[0]), float(p[1]))
    if best is None or math.dist(best, start) < DESCENT_STEP_M:
        return None
    return best
