"""Doors, plates and landmarks hung on the annotated walls: where each goes, and what
does not fit.

The annotated walls are the straight pieces of the free space's boundary (the corridor
rectangles' union, ``free_space.py``). An item snaps to the wall nearest its point in the
file, centred there and kept within the wall's ends; it takes a stretch of that wall as
wide as it is. Two things go wrong: a wall shorter than the item (it sticks out past
the wall's ends, into a junction or through a corner), and two items taking the same
stretch (one hangs through the other). ``WallPlacer`` is the one home of this: the
simulator hangs its items with it and logs what it reports, and ``pmnav validate``
places the file's doors and landmarks with it (``wall_item_warnings``), so validate
warns about what the simulator would trip on.

Validate counts a door with its frame (``DOOR_SPAN_M``) and a landmark by its kind
(``landmark_kinds``; a name plate as the 0.8 m plate of the file's signage). The
simulator counts the plates it draws, which in a building's own style are as wide as
their text, so it may still find an overlap among long-named plates that validate does
not.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

from pmnav_bt.errors import Problem
from pmnav_bt.map.building import Building
from pmnav_bt.map.floorplan import DOOR_WIDTH_M
from pmnav_bt.map.free_space import free_space_polygon, free_space_rings
from pmnav_bt.map.landmark_kinds import ELEVATOR, landmark_shape

DOOR_FRAME_M = 0.08  # a door frame's width each side of the leaf
DOOR_SPAN_M = DOOR_WIDTH_M + 2 * DOOR_FRAME_M  # the wall a door takes, with its frame
_EPS = 1e-6


def door_item(room_id: str) -> str:
    """How a message names the door of ``room_id`` (the simulator's and validate's)."""
    return f"the door of {room_id!r}"


def landmark_item(landmark_id: str) -> str:
    """How a message names landmark ``landmark_id``."""
    return f"landmark {landmark_id!r}"


@dataclass(frozen=True)
class WallSegment:
    """One straight piece of the free-space boundary; ``normal`` points into the free space."""

    a: tuple[float, float]
    b: tuple[float, float]
    normal: tuple[float, float]

    @property
    def length(self) -> float:
        return math.dist(self.a, self.b)

    @property
    def tangent(self) -> np.ndarray:
        d = np.subtract(self.b, self.a)
        return d / np.linalg.norm(d)

    def point(self, s: float) -> np.ndarray:
        """The point ``s`` metres from ``a`` towards ``b``."""
        return np.asarray(self.a, float) + s * self.tangent


def annotated_walls(free_space: Polygon | MultiPolygon) -> list[WallSegment]:
    """Every straight piece of the boundary of ``free_space``, going round each ring with
    the free space on the left (so the normal is the tangent turned left)."""
    walls = []
    for ring in free_space_rings(free_space):
        for a, b in zip(ring, ring[1:] + ring[:1], strict=True):
            d = np.subtract(b, a)
            length = float(np.linalg.norm(d))
            if length < _EPS:
                continue
            t = d / length
            walls.append(WallSegment(a, b, (float(-t[1]), float(t[0]))))
    return walls


@dataclass(frozen=True)
class Placement:
    """Where an item hangs: its wall (an index), the distance along it of its centre, and
    what is wrong there (empty when it fits)."""

    wall: int
    s: float
    problems: tuple[str, ...] = ()


class WallPlacer:
    """Items on walls, each taking a stretch ``[s - half, s + half]`` of one.

    ``walls`` is shared with the caller and may grow after the annotated walls (the
    simulator appends the real walls of a grid it hangs items on, ``share``); items
    snap only to the first ``annotated`` walls.
    """

    def __init__(self, walls: list[WallSegment]) -> None:
        self.walls = walls
        self.annotated = len(walls)
        self._taken: dict[int, list[tuple[float, float, str]]] = {}
        self._shift: dict[int, float] = {}  # wall -> how far its s runs ahead of its like's

    def nearest(self, pt: Sequence[float]) -> tuple[int, float]:
        """Index of the annotated wall nearest to ``pt`` and the distance along it."""
        q = np.asarray(pt, float)
        best, best_d, best_s = -1, math.inf, 0.0
        for i, w in enumerate(self.walls[: self.annotated]):
            a = np.asarray(w.a)
            s = float(np.clip(np.dot(q - a, w.tangent), 0.0, w.length))
            d = float(np.linalg.norm(q - w.point(s)))
            if d < best_d - 1e-9:
                best, best_d, best_s = i, d, s
        return best, best_s

    def _clash(self, wall: int, s0: float, s1: float) -> tuple[float, float, str] | None:
        d = self._shift.get(wall, 0.0)
        return next(
            ((o[0] + d, o[1] + d, o[2]) for o in self._taken.get(wall, [])
             if s1 - d > o[0] and s0 - d < o[1]),
            None,
        )  # fmt: skip

    def fits(self, wall: int, s0: float, s1: float) -> bool:
        """True when ``[s0, s1]`` lies on the wall and no item takes any of it."""
        w = self.walls[wall]
        if s0 < -_EPS or s1 > w.length + _EPS:
            return False
        return self._clash(wall, s0, s1) is None

    def occupy(self, wall: int, s: float, half: float, what: str = "another item") -> None:
        s -= self._shift.get(wall, 0.0)
        self._taken.setdefault(wall, []).append((s - half, s + half, what))

    def share(self, wall: int, like: int, shift: float = 0.0) -> None:
        """Make ``wall`` (a real wall an item on ``like`` hangs on) share its stretches; a
        point ``s`` along ``like`` is ``s + shift`` along ``wall`` (a real wall that runs
        on behind the annotated wall's start)."""
        self._taken[wall] = self._taken.setdefault(like, [])
        self._shift[wall] = shift + self._shift.get(like, 0.0)

    def place(
        self, what: str, pt: Sequence[float], half: float, *, at_foot: bool = False
    ) -> Placement:
        """Hang ``what`` (``2 * half`` wide) on the wall nearest ``pt``: centred at the
        foot of ``pt`` and kept within the wall's ends (on a wall too short for it,
        centred on the wall), its stretch taken, and what is wrong there.

        ``at_foot`` keeps it at the foot even where it then sticks out past an end: a
        lift, whose doorway and cabin are where the drawing has its door, whatever the
        corridors' walls round it."""
        wi, s = self.nearest(pt)
        w = self.walls[wi]
        where = "({:.2f}, {:.2f})".format(*w.point(w.length / 2.0))
        problems = []
        if w.length < 2.0 * half:
            problems.append(
                f"{what} needs {2 * half:.2f} m of wall, but the wall it is on (centre "
                f"{where}) is {w.length:.2f} m long: it sticks out past the wall's ends; "
                "move it to a longer wall"
            )
            s = s if at_foot else w.length / 2.0
        elif not at_foot:
            s = float(np.clip(s, half, w.length - half))
        elif not half <= s <= w.length - half:
            out = max(half - s, s + half - w.length)
            problems.append(
                f"{what} at ({w.point(s)[0]:.2f}, {w.point(s)[1]:.2f}) sticks out {out:.2f} m "
                "past its wall's end (it hangs where its point is); give it a straight wall"
            )
        other = self._clash(wi, s - half, s + half)
        if other is not None:
            at = "({:.2f}, {:.2f})".format(*w.point(s))
            problems.append(
                f"{what} at {at} overlaps {other[2]} on the same wall by "
                f"{min(s + half, other[1]) - max(s - half, other[0]):.2f} m: one hangs through "
                "the other; move one of them along the wall"
            )
        self.occupy(wi, s, half, what)
        return Placement(wi, s, tuple(problems))


def wall_item_warnings(b: Building) -> list[Problem]:
    """Doors and landmarks on a wall too short for them, or overlapping another item on
    their wall, placed as the simulator places them (doors first, then landmarks)."""
    placer = WallPlacer(annotated_walls(free_space_polygon(b)))
    items = [
        (f"rooms[{i}].door", door_item(r.id), r.door, DOOR_SPAN_M / 2.0)
        for i, r in enumerate(b.rooms)
    ] + [
        (f"landmarks[{i}].pos", landmark_item(lm.id), lm.pos, landmark_shape(lm.kind).span_m / 2)
        for i, lm in enumerate(b.landmarks)
    ]
    lifts = {landmark_item(lm.id) for lm in b.landmarks if landmark_shape(lm.kind) is ELEVATOR}
    out = []
    for field, what, pos, half in items:
        placed = placer.place(what, pos, half, at_foot=what in lifts)
        out += [Problem(field, m) for m in placed.problems]
    return out
