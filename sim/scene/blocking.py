"""A corridor closed on purpose: the barrier an episode asks for (``Episode.blocked``).

The scene never blocks the only way to a goal by itself (clutter keeps a robot's width
free); an episode that wants to test what the robot does when a way is closed (cleaning,
works, a fire door held shut) names priori-map segments, and each gets a barrier across
the whole corridor at its middle: a solid, waist-high, striped board spanning the open
floor from wall to wall. It counts as an obstacle of the building as built, so SPL's
shortest path goes round it where another way exists.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import shapely
from shapely.geometry import LineString

from pmnav_bt.errors import PmNavError, UnknownNameError
from pmnav_bt.seams import OBSTACLE_LABEL
from pmnav_bt.sim.scene.host import BoxWorld

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.map.priori_map import PrioriMap

BARRIER_DEPTH_M = 0.3
BARRIER_HEIGHT_M = 1.0
BARRIER_RGBA = ((0.95, 0.80, 0.10, 1.0), (0.10, 0.10, 0.10, 1.0))  # yellow and black stripes
STRIPES = 6
REACH_M = 10.0  # how far to each side of the centre line a barrier may reach


class BlockError(PmNavError):
    """A segment to block that the building does not have, or has no floor at its middle."""


def block_segment(world: BoxWorld, pm: PrioriMap, ref: str) -> list[int]:
    """A barrier across the corridor at the middle of priori-map segment ``ref`` ("seg13");
    the body ids of its stripes."""
    try:
        seg = pm.segment(ref)
    except UnknownNameError as err:
        raise BlockError(f"blocked {err} ({pm.building.name})") from None
    a, b = pm.node_xy(seg.a), pm.node_xy(seg.b)
    mid = (a + b) / 2.0
    d = b - a
    if float(np.hypot(*d)) < 1e-6:
        raise BlockError(f"blocked segment {ref!r} has no length")
    across = np.array([-d[1], d[0]]) / float(np.hypot(*d))
    line = LineString([mid - across * REACH_M, mid + across * REACH_M])
    chord = chord_through(world.floor_space().intersection(line), mid)
    if chord is None:
        raise BlockError(f"blocked segment {ref!r}: no open floor at its middle")
    p0, p1 = (np.asarray(c, float) for c in chord.coords[:2])
    width = float(np.hypot(*(p1 - p0)))
    yaw = math.atan2(p1[1] - p0[1], p1[0] - p0[0])
    bodies = []
    for k in range(STRIPES):
        c = p0 + (p1 - p0) * (k + 0.5) / STRIPES
        bodies.append(
            world.add_box(
                (float(c[0]), float(c[1]), BARRIER_HEIGHT_M / 2.0),
                (width / STRIPES / 2.0, BARRIER_DEPTH_M / 2.0, BARRIER_HEIGHT_M / 2.0),
                yaw,
                BARRIER_RGBA[k % 2],
                OBSTACLE_LABEL,
            )
        )
    return bodies


def chord_through(cut, point: np.ndarray) -> LineString | None:
    """The piece of ``cut`` (a line's intersection with the floor) nearest ``point``."""
    pieces = [g for g in getattr(cut, "geoms", [cut]) if isinstance(g, LineString) and g.length]
    if not pieces:
        return None
    here = shapely.Point(point)
    return min(pieces, key=lambda g: g.distance(here))
