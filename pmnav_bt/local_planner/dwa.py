"""The dynamic window approach: the velocity command that drives well for the next 2 s.

What it models: Fox, Burgard and Thrun's DWA (1997) as Nav2's DWB controller runs it,
with Brock and Khatib's navigation function for the goal term (the "global dynamic
window": progress measured along free space, so a box on the way is gone round instead of
being a local minimum in front of it). Every control period:

1. **The window**: the (v, w) the body can reach within one period from the command in
   force, under its accelerations (``Dynamics``), inside its speed limits; sampled on a
   grid (forward only: the Create 3 reverses at most 0.15 m, ``backup_limit``).
2. **Rollouts**: each sample held for ``HORIZON_S`` along its arc.
3. **Admissible**: every pose of the rollout at least the costmap's lethal distance from
   anything (or, where the body already stands closer, no closer than it stands: it may
   always turn away).
   And every pose where the costmap has seen the floor free all round the body, or on
   the drive's straight line, or round something marked (``passable``): the camera,
   1.6 m up, does not see the floor within 3.7 m of it, so a robot may leave the line
   only onto floor it saw from farther off or to go round what it saw (the line itself is
   trusted as the direct drive trusts it).
4. **Score** (lower is better): progress along the navigation function, the costmap's
   cost along the way (clearance), the heading at the end towards the goal, and the
   distance from the drive's straight line (stay on the corridor's centre line where it
   is free). None admissible: stop (``None``).

The navigation function (``navigation``: fast marching from the goal over the cells that
are not lethal, scikit-fmm) is also the planner's answer to "is there a way at all" in
the window: where it does not reach the robot, the way is shut.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import skfmm
from scipy.ndimage import distance_transform_edt

from pmnav_bt.local_planner.costmap import CostGrid
from pmnav_bt.seams import CREATE3_MAX_ANGULAR, CREATE3_MAX_LINEAR

# The Create 3's wheel acceleration limit (its motion control's ``wheel_accel_limit``,
# 900 mm/s^2 by default); turning, each wheel at that rate over its 0.235 m wheelbase.
CREATE3_ACCEL_LINEAR = 0.9  # m/s^2
CREATE3_ACCEL_ANGULAR = 2.0 * CREATE3_ACCEL_LINEAR / 0.235  # rad/s^2
HORIZON_S = 1.8  # a rollout: 0.55 m at full speed, twice the braking and turning room
STEP_S = 0.1  # rollout resolution: 3 cm at full speed, under a cell
LINEAR_SAMPLES = 6
ANGULAR_SAMPLES = 15
# Score weights: progress dominates; clearance keeps off the inflation; heading and the
# drive's line break ties (a robot that ends facing its goal, on the centre line).
W_PROGRESS, W_CLEARANCE, W_HEADING, W_LINE = 1.0, 0.5, 0.15, 0.1
LOCAL_GOAL_MARGIN_M = 0.4  # a goal beyond the window is aimed at this far inside its edge
GOAL_SEED_M = 0.3  # the navigation function starts from the free cells this near the goal
OWN_CELLS_M = 0.3  # cells this near the robot are free to the navigation function
LINE_BAND_M = 0.05  # the line is trusted this far beyond the lethal distance either side
# The floor this near something marked is trusted too: the way round it. The camera sees
# the floor beside a box from afar, but the floor just past it lies in the box's shadow
# and then under the camera's view; what stood there taller than the box was seen above it.
ROUND_M = 1.0


@dataclass(frozen=True)
class Dynamics:
    """The body's limits: speeds (m/s, rad/s), accelerations (m/s^2, rad/s^2) and the
    control period (s) the window is reached in."""

    max_linear: float = CREATE3_MAX_LINEAR
    max_angular: float = CREATE3_MAX_ANGULAR
    accel_linear: float = CREATE3_ACCEL_LINEAR
    accel_angular: float = CREATE3_ACCEL_ANGULAR
    period: float = 0.1


@dataclass(frozen=True)
class Navigation:
    """Metres to go to ``goal`` (odometry) through free cells of ``grid``; a masked array,
    masked where lethal or cut off."""

    goal: tuple[float, float]
    grid: CostGrid
    field: np.ma.MaskedArray

    def at(self, x, y) -> np.ndarray:
        """Metres to go from odometry points (inf where there is no way or off the window)."""
        i, j, inside = self.grid.cells(x, y)
        values = self.field.filled(math.inf)[i, j]
        return np.where(inside, values, math.inf)


@dataclass(frozen=True)
class Choice:
    """The command chosen: (v, w), its score, and how many samples were admissible."""

    v: float
    w: float
    score: float
    admissible: int


def local_goal(grid: CostGrid, x: float, y: float, goal: tuple[float, float]):
    """``goal`` if it lies well inside the window, else the point towards it that does."""
    n = grid.dist.shape[0] * grid.resolution
    lo_x, lo_y = grid.origin
    m = LOCAL_GOAL_MARGIN_M
    if lo_x + m <= goal[0] <= lo_x + n - m and lo_y + m <= goal[1] <= lo_y + n - m:
        return float(goal[0]), float(goal[1])
    reach = n / 2.0 - m
    a = math.atan2(goal[1] - y, goal[0] - x)
    return x + reach * math.cos(a), y + reach * math.sin(a)


def passable(grid: CostGrid, line) -> np.ndarray:
    """Cells the body's centre may cross: those whose lethal disc lies all on floor seen
    free, within ``ROUND_M`` of something marked, or within ``LINE_BAND_M`` and the lethal
    distance of ``line`` (odometry segment; None: none trusted)."""
    trusted = grid.seen | (grid.dist <= ROUND_M)
    if line is not None:
        n, r = grid.dist.shape[0], grid.resolution
        cx = grid.origin[0] + (np.arange(n) + 0.5) * r
        cy = grid.origin[1] + (np.arange(n) + 0.5) * r
        xx, yy = np.meshgrid(cx, cy)
        trusted |= _off_line(xx, yy, line) <= grid.lethal_m + LINE_BAND_M
    return distance_transform_edt(trusted) * grid.resolution >= grid.lethal_m


def navigation(
    grid: CostGrid, x: float, y: float, goal: tuple[float, float], ok: np.ndarray | None = None
) -> Navigation:
    """The navigation function towards ``goal`` (odometry) for a robot at (x, y), over
    the cells ``ok`` (``passable``; None: all) that are not lethal."""
    g = local_goal(grid, x, y, goal)
    r = grid.resolution
    n = grid.dist.shape[0]
    cx = grid.origin[0] + (np.arange(n) + 0.5) * r
    cy = grid.origin[1] + (np.arange(n) + 0.5) * r
    blocked = grid.dist < grid.lethal_m
    if ok is not None:
        blocked |= ~ok
    own = np.hypot(cx[None, :] - x, cy[:, None] - y) <= OWN_CELLS_M
    blocked &= ~own
    seed = (np.hypot(cx[None, :] - g[0], cy[:, None] - g[1]) <= GOAL_SEED_M) & ~blocked
    if not seed.any():
        return Navigation(g, grid, np.ma.masked_all((n, n)))
    phi = np.ma.MaskedArray(np.where(seed, -1.0, 1.0), blocked)
    field = skfmm.distance(phi, dx=r)
    field = np.ma.MaskedArray(np.maximum(field.filled(math.inf), 0.0), np.ma.getmaskarray(field))
    return Navigation(g, grid, field)


def window(v0: float, w0: float, dyn: Dynamics) -> tuple[np.ndarray, np.ndarray]:
    """The (v, w) samples reachable within one period from (v0, w0), all pairs."""
    dv, dw = dyn.accel_linear * dyn.period, dyn.accel_angular * dyn.period
    v_lo, v_hi = max(0.0, v0 - dv), min(dyn.max_linear, max(0.0, v0 + dv))
    w_lo, w_hi = max(-dyn.max_angular, w0 - dw), min(dyn.max_angular, w0 + dw)
    vs = np.unique(np.linspace(v_lo, v_hi, LINEAR_SAMPLES))
    ws = np.linspace(w_lo, w_hi, ANGULAR_SAMPLES)
    if w_lo <= 0.0 <= w_hi:
        ws = np.unique(np.append(ws, 0.0))
    v, w = np.meshgrid(vs, ws, indexing="ij")
    return v.ravel(), w.ravel()


def rollout(x: float, y: float, yaw: float, v: np.ndarray, w: np.ndarray):
    """Poses (x, y, yaw; samples x steps) of each (v, w) held for ``HORIZON_S``."""
    t = np.arange(1, int(round(HORIZON_S / STEP_S)) + 1) * STEP_S
    v, w = v[:, None], w[:, None]
    th = yaw + w * t
    turning = np.abs(w) > 1e-6
    safe_w = np.where(turning, w, 1.0)
    px = np.where(turning, x + v / safe_w * (np.sin(th) - math.sin(yaw)), x + v * t * math.cos(yaw))
    py = np.where(turning, y - v / safe_w * (np.cos(th) - math.cos(yaw)), y + v * t * math.sin(yaw))
    return px, py, th


def choose(
    grid: CostGrid,
    nav: Navigation | None,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    goal: tuple[float, float],
    line: tuple[tuple[float, float], tuple[float, float]] | None,
    dyn: Dynamics,
    ok: np.ndarray | None = None,
) -> Choice | None:
    """The best admissible (v, w) from odometry ``pose`` towards ``goal`` (see the module's
    docstring); ``nav``: the navigation function for this goal (None: straight-line
    distance); ``line``: the drive's straight line (odometry), or None; ``ok``: the
    cells the body may cross (``passable``; None: all)."""
    x, y, yaw = pose
    v, w = window(*velocity, dyn)
    px, py, th = rollout(x, y, yaw, v, w)
    clear = grid.clearance(px, py)
    here = float(grid.clearance(np.array([x]), np.array([y]))[0])
    fine = (clear >= min(grid.lethal_m, here - 1e-6)).all(axis=1)
    if ok is not None:
        i, j, inside = grid.cells(px, py)
        own = np.hypot(px - x, py - y) <= OWN_CELLS_M
        fine &= (ok[i, j] | ~inside | own).all(axis=1)
    ok = fine
    ends = (px[:, -1], py[:, -1])
    to_go = nav.at(*ends) if nav is not None else np.full(len(v), math.inf)
    if np.isfinite(to_go).any():
        # Never less than the straight distance: the last metres, inside the goal's seed
        # (where the navigation function is 0), are driven by it.
        g = nav.goal
        to_go = np.maximum(to_go, np.hypot(ends[0] - g[0], ends[1] - g[1]))
        start = max(float(nav.at(np.array([x]), np.array([y]))[0]), math.hypot(x - g[0], y - g[1]))
        if not math.isfinite(start):  # the robot stands cut off (too near something): out
            start = float(to_go[np.isfinite(to_go)].max())
    else:  # no navigation function for this goal, or none reaching: straight distance
        g = nav.goal if nav is not None else local_goal(grid, x, y, goal)
        to_go, start = np.hypot(ends[0] - g[0], ends[1] - g[1]), math.hypot(x - g[0], y - g[1])
    ok &= np.isfinite(to_go)
    if not ok.any():
        return None
    progress = (to_go - start) / (dyn.max_linear * HORIZON_S)
    cost = grid.cost(clear).max(axis=1)
    bearing = np.arctan2(g[1] - py[:, -1], g[0] - px[:, -1]) - th[:, -1]
    facing = np.abs((bearing + math.pi) % (2.0 * math.pi) - math.pi) / math.pi
    near_goal = np.hypot(px[:, -1] - g[0], py[:, -1] - g[1]) < 0.2
    facing = np.where(near_goal, 0.0, facing)  # at the goal, any heading will do
    off_line = np.zeros_like(progress) if line is None else _off_line(px[:, -1], py[:, -1], line)
    score = (
        W_PROGRESS * progress
        + W_CLEARANCE * cost
        + W_HEADING * facing
        + W_LINE * np.minimum(off_line, 1.0)
    )
    score = np.where(ok, score, math.inf)
    k = int(np.argmin(score))
    return Choice(float(v[k]), float(w[k]), float(score[k]), int(ok.sum()))


def _off_line(x: np.ndarray, y: np.ndarray, line) -> np.ndarray:
    """Distance (m) from points to the segment ``line``."""
    (ax, ay), (bx, by) = line
    dx, dy = bx - ax, by - ay
    n2 = dx * dx + dy * dy
    t = np.clip(((x - ax) * dx + (y - ay) * dy) / n2, 0.0, 1.0) if n2 > 0 else 0.0
    return np.hypot(x - (ax + t * dx), y - (ay + t * dy))
