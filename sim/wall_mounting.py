"""Doors, signs and landmarks hung on the grid's real walls (``SimWorld(walls="grid")``).

With walls from a ros_map, the building file's corridor rectangles no longer make the
walls, yet the file's doors, signs and landmarks are drawn on them: where the annotation
is narrower than the real corridor they would float in the corridor, up to most of a
metre in front of the wall (0.6-0.8 m in examples/hospital), where no robot would find
them. Here each item is moved onto the real wall (``pmnav_bt.map.wall_surface``): the
same place along its annotated wall, the real wall's depth and, where it is well
fitted, its direction. A door also gets its opening cut through the grid's wall, and
the grid cells just in front of every item are kept free so a ragged wall does not
swallow it. What moved is recorded (``SimWorld.moved_items``) and logged once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.map.floorplan import FloorPlanImage
from pmnav_bt.map.wall_surface import RealWalls, WallMount

ITEM_CLEAR_BEHIND = 0.05  # m of grid wall cleared behind every item (its mounting)
ITEM_CLEAR_FRONT = 0.3  # ... and in front of it, where a ragged wall bulges past it
DOOR_OPENING_MAX_M = 0.6  # a room behind a door wall at most this thick is opened into
DOORWAY_DEPTH_M = 0.3  # else the opening is a doorway this deep (a room the scan never saw)
MOVED_M = 0.1  # items moved less than this (two grid cells) count as in place
# A file point this close to the real wall's face (or inside the wall: a drawn wall is
# about 0.15 m thick, the point on its centre line) is where the item is on that wall.
IN_WALL_M = 0.3


@dataclass(frozen=True)
class MovedItem:
    """One item as the file annotated it and as the simulator hung it on the real wall.

    ``found`` is False when no wall was found within the search range: the item then
    stays on its annotated wall.
    """

    id: str
    kind: str  # "door", "sign" or the landmark's kind
    label: str
    annotated: tuple[float, float]
    placed: tuple[float, float]
    found: bool

    @property
    def distance(self) -> float:
        return math.dist(self.annotated, self.placed)

    @property
    def shift(self) -> tuple[float, float]:
        """``placed - annotated`` (map frame)."""
        return (self.placed[0] - self.annotated[0], self.placed[1] - self.annotated[1])


class GridMounts:
    """The real walls of one world's grid, and which of its wall segments are real walls.

    A mounted item gets a wall segment of its own (``SimWorld.walls``), parallel to the
    real wall and measured in the same ``s`` as the annotated one it replaces, so every
    part of the item (a door's frame, the plate beside it) keeps its place along the wall.
    """

    def __init__(self, plan: FloorPlanImage) -> None:
        self.walls = RealWalls(plan)
        self.parent: dict[int, int] = {}  # mounted wall segment -> its annotated one
        self.shift: dict[int, float] = {}  # mounted segment -> s there less s on its parent
        self.missed: set[int] = set()  # mounted segments where no real wall was found

    def real_wall(
        self, a, b, normal, s: float, half: float, at=None
    ) -> tuple[tuple, tuple, tuple, bool, float]:
        """Ends and normal of the real wall through the item at ``s`` on annotated wall
        ``a``-``b`` (``half`` its half width), whether a wall was found there, and how far
        the real wall's start lies behind the annotated one's (the ``shift`` of ``s``).

        The real wall runs as far as the annotated wall does and on where the grid's wall
        runs on straight (``RealWalls.extent``): the annotated walls stop where corridors
        meet and where a turn in front of a door ends, and a door on a slanted wall sits
        on a sliver of the corridors' outline, while its plate and frame hang on the wall
        the building has (a door's plate on a 0.28 m annotated wall went above the door).

        ``at``: the item's file point. Where it lies in the real wall or on its face
        (within ``IN_WALL_M``: an imported RMF door, drawn where the door is), the item
        hangs there, not where its annotated wall puts it: one width per corridor cannot
        follow a hall's walls, and an item is kept within its annotated wall's ends, which
        the corridors' outline cuts short where corridors meet (a door moved a metre or
        more along the real wall, or onto another wall)."""
        a, b, n = (np.asarray(v, float) for v in (a, b, normal))
        tan = (b - a) / np.linalg.norm(b - a)
        m: WallMount | None = None
        if at is not None:
            face = self._face(np.asarray(at, float), n)
            if face is not None:
                m = self.walls.mount(np.asarray(at, float), face, half, search=IN_WALL_M)
        if m is None:
            m = self.walls.mount(a + s * tan, n, half)
        if m is None:
            return _xy(a), _xy(b), _xy(n), False, 0.0
        nn = np.asarray(m.normal)
        tt = np.array([nn[1], -nn[0]])  # the real wall's direction, same sense as a -> b
        back, forth = self.walls.extent(m.point, nn)
        shift = max(0.0, back - s)
        length = max(float(np.linalg.norm(b - a)), s + forth) + shift
        start = np.asarray(m.point) - (s + shift) * tt
        return _xy(start), _xy(start + length * tt), _xy(nn), True, shift

    def _face(self, pt: np.ndarray, normal: np.ndarray) -> np.ndarray | None:
        """The unit normal of the real wall face nearest ``pt`` (towards the free space),
        that face within ``IN_WALL_M`` and not facing away from the annotated ``normal``'s
        corridor; None when ``pt`` is not in or on a real wall."""
        angles = np.radians(np.arange(0.0, 360.0, 10.0))
        ways = np.stack([np.cos(angles), np.sin(angles)], 1)
        ways = ways[ways @ normal > -0.5]
        step = self.walls.plan.resolution / 2.0
        for r in np.arange(0.0, IN_WALL_M + 1e-9, step):
            free = self.walls.free_at(pt[None, :] + r * ways)
            if r == 0.0 and free.any():
                return None  # on the free floor: not in a wall
            if free.any():
                return ways[free].mean(axis=0) / np.linalg.norm(ways[free].mean(axis=0))
        return None

    def record(self, mounted: int, annotated: int, found: bool, shift: float = 0.0) -> None:
        self.parent[mounted] = annotated
        self.shift[mounted] = shift
        if not found:
            self.missed.add(mounted)

    def annotated(self, wall: int, s: float) -> tuple[int, float]:
        """Where ``s`` along wall ``wall`` is on the annotated wall it was mounted for (its
        parent, in that wall's measure); a wall not mounted here is its own."""
        return self.parent.get(wall, wall), s - self.shift.get(wall, 0.0)


def moved_items(world) -> list[MovedItem]:
    """Every door, sign and landmark of a grid-walled ``world``: annotated and placed."""
    mounts: GridMounts = world._mounts
    out = []
    for item in (*world.doors.values(), *world.signs.values(), *world.landmarks.values()):
        where = world._where.get(item.label)
        if where is None or where[0] not in mounts.parent:
            continue  # a styled plate: it hangs by its door, on the door's wall
        wi, s = where
        parent, s_parent = mounts.annotated(wi, s)
        was, now = world.walls[parent].point(s_parent), world.walls[wi].point(s)
        found = wi not in mounts.missed
        out.append(MovedItem(item.id, item.kind, item.label, _xy(was), _xy(now), found))
    return out


def summary(moved: list[MovedItem]) -> str:
    """One line: how many items moved onto the grid's walls, how far, and which found none."""
    far = [m.distance for m in moved if m.found and m.distance >= MOVED_M]
    missed = [m for m in moved if not m.found]
    line = f"{len(far)} of {len(moved)} doors, signs and landmarks moved onto the grid's walls"
    if far:
        line += f" (mean {np.mean(far):.2f} m, max {max(far):.2f} m)"
    if missed:
        line += f"; no wall within reach of {len(missed)}: " + ", ".join(
            f"{m.kind} {m.id}" for m in missed
        )
    return line


def grid_clearings(world) -> list[np.ndarray]:
    """Map-frame polygons whose grid cells the walls keep free: a strip in front of every
    item, each door's opening through the wall behind it, and each lift's doorway and
    cabin (``Cabin.clearings``)."""
    mounts: GridMounts = world._mounts
    out = []
    for it in (
        *world.doors.values(),
        *world.signs.values(),
        *world.landmarks.values(),
        *world.landmark_signs.values(),
        *world.directional_signs.values(),
    ):
        out.append(_strip(it, ITEM_CLEAR_BEHIND, ITEM_CLEAR_FRONT, 0.05))
    for door in world.doors.values():
        c, n = np.asarray(door.centre), np.asarray(door.normal)
        behind = mounts.walls.thickness(c, n, DOOR_OPENING_MAX_M)
        depth = DOORWAY_DEPTH_M if behind is None else behind + mounts.walls.plan.resolution
        out.append(_strip(door, depth, 0.0, 0.0))
    for cabin in world.cabins.values():  # a lift's doorway, and its cabin in the shaft
        c, n = np.asarray(cabin.centre), -np.asarray(cabin.into)
        behind = mounts.walls.thickness(c, n, DOOR_OPENING_MAX_M)
        out.extend(cabin.clearings(0.0 if behind is None else behind))
    return out


def _strip(item, behind: float, front: float, extra: float) -> np.ndarray:
    """The rectangle ``behind`` m into the wall to ``front`` m out of it, over the item's
    width plus ``extra`` each side."""
    c, n = np.asarray(item.centre), np.asarray(item.normal)
    t = np.array([n[1], -n[0]]) * (item.width / 2.0 + extra)
    back, fore = c - n * behind, c + n * front
    return np.array([back - t, back + t, fore + t, fore - t])


def _xy(v) -> tuple[float, float]:
    return float(v[0]), float(v[1])
