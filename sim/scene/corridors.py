"""The corridors of a building as the scene places things in them: each corridor (an edge
of the corridor graph) with its centre line, its two wall sides and its junction ends.

A corridor runs from waypoint ``a`` to ``b``; ``s`` is metres along it from ``a`` and
``lateral`` metres to the left of the direction a -> b. Its walls are ``half_width``
either side of the centre line (``pmnav_bt.map.free_space``: each corridor is its centre
line buffered by half its width). A waypoint is a junction when three or more corridors
meet there or the way turns there (by more than ``TURN_DEG``): the scene keeps such
places clear, where a robot turns and looks into the next corridor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from pmnav_bt.map.building import Building

TURN_DEG = 20.0  # a way that bends by more than this at a waypoint turns there


@dataclass(frozen=True)
class Corridor:
    """One corridor: centre line from ``a`` to ``b`` (map frame), ``half_width``, and whether
    each end (``a``, ``b``) is a junction or a turn."""

    index: int
    a_id: str
    b_id: str
    a: tuple[float, float]
    b: tuple[float, float]
    half_width: float
    junction_at: tuple[bool, bool]

    @cached_property
    def length(self) -> float:
        return math.dist(self.a, self.b)

    @cached_property
    def along(self) -> np.ndarray:
        """Unit vector from a to b."""
        return (np.asarray(self.b, float) - self.a) / max(self.length, 1e-9)

    @cached_property
    def left(self) -> np.ndarray:
        """Unit vector to the left of a -> b."""
        u = self.along
        return np.array([-u[1], u[0]])

    def point(self, s: float, lateral: float = 0.0) -> np.ndarray:
        """The point ``s`` m along the centre line and ``lateral`` m to its left."""
        return np.asarray(self.a, float) + s * self.along + lateral * self.left

    def local(self, xy) -> tuple[float, float]:
        """(s, lateral) of a map point."""
        d = np.asarray(xy, float) - self.a
        return float(d @ self.along), float(d @ self.left)


def corridors(building: Building) -> list[Corridor]:
    """Every corridor of ``building`` (one per edge, in file order) with its junction ends."""
    pos = {w.id: np.asarray(w.pos, float) for w in building.waypoints}
    nbrs: dict[str, list[str]] = {}
    for e in building.edges:
        nbrs.setdefault(e.a, []).append(e.b)
        nbrs.setdefault(e.b, []).append(e.a)

    def junction(w: str) -> bool:
        ns = nbrs.get(w, [])
        if len(ns) >= 3:
            return True
        if len(ns) == 2:
            u, v = pos[ns[0]] - pos[w], pos[ns[1]] - pos[w]
            cos = float(u @ v / max(np.linalg.norm(u) * np.linalg.norm(v), 1e-9))
            return math.degrees(math.acos(max(-1.0, min(1.0, -cos)))) > TURN_DEG
        return False

    return [
        Corridor(
            i,
            e.a,
            e.b,
            (float(pos[e.a][0]), float(pos[e.a][1])),
            (float(pos[e.b][0]), float(pos[e.b][1])),
            building.edge_width(e) / 2.0,
            (junction(e.a), junction(e.b)),
        )
        for i, e in enumerate(building.edges)
    ]


def junction_points(building: Building) -> list[tuple[tuple[float, float], float]]:
    """Every junction or turn waypoint with the widest half width of its corridors."""
    out: dict[str, tuple[tuple[float, float], float]] = {}
    for c in corridors(building):
        for at, wid, xy in ((0, c.a_id, c.a), (1, c.b_id, c.b)):
            if c.junction_at[at]:
                hw = max(out.get(wid, (xy, 0.0))[1], c.half_width)
                out[wid] = (xy, hw)
    return list(out.values())
