"""Snap a pose estimate that has drifted off the corridors back onto the one it must be on.

A robot is always on a corridor; an estimate beside one is odometry drift. The nearest
plausible corridor is the one that best explains the estimate: close (within the pose
uncertainty) and running the way the robot heads. The snapped estimate keeps the
position along the corridor and takes the uncertainty across it from the corridor width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.priori_map import PrioriMap, Segment
from pmnav_bt.seams import Pose2D

HEADING_SIGMA = math.radians(25.0)  # how far the heading may be off a corridor's axis
MAX_SIGMAS = 4.0  # farther than this many sigmas from every corridor: not plausible


class OffMapError(PmNavError):
    """No corridor is plausibly where the estimate says the robot is."""


@dataclass(frozen=True)
class Snapped:
    """The estimate on ``segment`` at fraction ``t``; ``moved`` m from where it was."""

    pose: Pose2D
    segment: Segment
    t: float
    moved: float
    sigma: float  # position uncertainty along the corridor (m); across it, the width


def snap_to_corridor(pm: PrioriMap, pose: Pose2D, sigma: float, candidates: int = 6) -> Snapped:
    """The pose moved onto the most plausible nearby corridor segment.

    ``sigma``: the estimate's position uncertainty (m). Segments are scored by the
    distance beyond their half-width (in sigmas) and by how well the heading runs
    along them; an estimate inside a corridor stays where it is.
    """
    a = np.array([pm.nodes[s.a].pos for s in pm.segments], dtype=float)
    b = np.array([pm.nodes[s.b].pos for s in pm.segments], dtype=float)
    p = np.array([[pose.x, pose.y]])
    # Distance to every segment (maps are small: a few hundred segments at most).
    d = b - a
    t = np.clip(((p - a) * d).sum(1) / np.maximum((d * d).sum(1), 1e-12), 0.0, 1.0)
    foot = a + t[:, None] * d
    dist = np.linalg.norm(foot - p, axis=1)
    order = np.argsort(dist)[:candidates]
    best, best_cost = None, math.inf
    s = max(sigma, 0.3)
    for i in order:
        seg = pm.segments[int(i)]
        beyond = max(0.0, float(dist[i]) - seg.width / 2.0)
        turn = abs(wrap_angle(2.0 * (pose.yaw - seg.heading))) / 2.0
        cost = (beyond / s) ** 2 + (turn / HEADING_SIGMA) ** 2
        if cost < best_cost:
            best, best_cost = int(i), cost
    seg = pm.segments[best]
    beyond = max(0.0, float(dist[best]) - seg.width / 2.0)
    if beyond > MAX_SIGMAS * s:
        raise OffMapError(
            f"pose ({pose.x:.2f}, {pose.y:.2f}) is {dist[best]:.1f} m from the nearest "
            f"corridor ({seg.name}), beyond {MAX_SIGMAS:g} x its uncertainty ({s:.1f} m)"
        )
    if beyond == 0.0:
        q = p[0]
    else:  # onto the corridor, just inside its wall
        inside = max(0.0, seg.width / 2.0 - 0.4)
        q = foot[best] + (p[0] - foot[best]) * (inside / float(dist[best]))
    moved = float(np.linalg.norm(q - p[0]))
    return Snapped(Pose2D(float(q[0]), float(q[1]), pose.yaw), seg, float(t[best]), moved, s)
