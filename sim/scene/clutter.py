"""Clutter along the corridor walls: where benches, chairs, carts, beds, plants and notice
boards go, so that the corridor still looks used and every goal can still be reached.

The config's ``world.clutter_per_10m`` is the number of items per 10 m of wall (the
free-space boundary), ``world.clutter_before_signs`` the fraction of them placed in
front of a sign plate (partly hiding it: only items that reach above the plate's lower
edge go there); the kinds follow the building's kind (beds only in hospitals, notice
boards mostly in schools, plants in offices: ``KIND_WEIGHTS``). Everything is drawn from
``world.rng("clutter")``.

The placement keeps every episode solvable, the way a building's fire code keeps an
escape route clear:

- nothing stands within ``SUCCESS_RADIUS_M`` of a door (the stop point and the whole
  success disc stay clear), at a junction or turn (``JUNCTION_CLEAR_M`` beyond the
  crossing), or in front of a landmark that stands on the floor (elevators, stairs,
  desks: ``LANDMARK_CLEAR_M`` either side, across the corridor);
- an item stands against a wall (never across the opening of a side corridor), and
  never within ``CENTRE_BAND_M`` of any corridor's centre line, where episodes start and
  the tree drives, so the centre line stays drivable for the robot everywhere;
- the free width beside an item (to the other wall, or to an item across the corridor)
  is at least ``PASSAGE_M``; items on one wall keep ``ITEM_GAP_M`` apart;
- only the items placed in front of a sign may stand before one.

Items are solid (the robot collides with them) and count in ``obstacle_footprints``:
they are part of the building as built, so SPL's shortest path goes round them.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely
from shapely.geometry import LineString, MultiLineString, Point, Polygon

from pmnav_bt.eval.task import SUCCESS_RADIUS_M
from pmnav_bt.seams import CREATE3_RADIUS_M, OBSTACLE_LABEL
from pmnav_bt.sim.scene.bodies import Envelope, compound_body, footprint
from pmnav_bt.sim.scene.corridors import Corridor, corridors, junction_points
from pmnav_bt.sim.scene.furniture import BUILDERS, ON_WALL, Shape
from pmnav_bt.sim.scene.host import Mounted, SceneWorld

log = logging.getLogger(__name__)

# The robot (Create 3, 0.17 m radius) driving the centre line keeps 0.1 m off any item.
CENTRE_BAND_M = CREATE3_RADIUS_M + 0.1
# Clear width beside an item: the accessible-route minimum (0.915 m, ADA 403.5.1),
# 2.6 robot diameters: room for the robot with its odometry drift, or a person, to pass.
PASSAGE_M = 0.9
ITEM_GAP_M = 0.25  # between items along one wall
JUNCTION_CLEAR_M = 1.0  # kept clear beyond the crossing square of a junction or turn
LANDMARK_CLEAR_M = 0.5  # kept clear either side of a floor-standing landmark
SIGN_FRONT_M = 1.0  # how far in front of a sign plate ordinary clutter keeps off
SIGN_COVER = 0.7  # an item before a sign is shifted by up to this much of the overlap span
WALL_GAP_M = 0.02  # furniture stands this far off the wall (clear of the skirting)
TRIES_PER_ITEM = 60
TALL_TRIES = 8  # draws of an item tall enough to stand before a given sign
# Tries at an item before a sign; then it stands elsewhere (where plates hang high, or
# every sign is on or above its door, few sites exist, and each try builds shapes).
BEFORE_SIGN_TRIES = 12
MIN_CORRIDOR_M = 0.5  # shorter corridors (stubs joining others) carry no clutter

KIND_WEIGHTS: dict[str, dict[str, float]] = {
    "hospital": {"bench": 2, "chair": 3, "cart": 3, "bed": 2, "plant": 1.5, "notice_board": 1},
    "school": {"bench": 3, "chair": 1, "cart": 0.5, "bed": 0, "plant": 1, "notice_board": 3},
    "office": {"bench": 0.5, "chair": 2, "cart": 0.5, "bed": 0, "plant": 2, "notice_board": 1.5},
}
DEFAULT_WEIGHTS = {"bench": 1, "chair": 1, "cart": 1, "bed": 0, "plant": 1, "notice_board": 1}


@dataclass(frozen=True)
class ClutterItem:
    """One placed item: its ``kind``, body, footprint (``centre``, ``length`` along the wall,
    ``depth`` out of it, the wall's inward ``normal``), heights, and where it stands: the
    corridor, the side (+1 left of a -> b, -1 right), ``s`` along the corridor, and the
    label of the sign it stands in front of ("" if none)."""

    kind: str
    body: int
    centre: tuple[float, float]
    normal: tuple[float, float]
    length: float
    depth: float
    bottom: float
    top: float
    corridor: int
    side: int
    s: float
    before_sign: str = ""

    @property
    def yaw(self) -> float:
        """The item's x axis (along the wall) as a heading."""
        return math.atan2(-self.normal[0], self.normal[1])

    @cached_property
    def footprint(self) -> Polygon:
        return footprint(*self.centre, self.yaw, self.length / 2.0, self.depth / 2.0)


@dataclass(frozen=True)
class _Site:
    corridor: Corridor
    side: int
    s: float
    shape: Shape
    kind: str

    @property
    def normal(self) -> np.ndarray:
        return -self.side * self.corridor.left

    @property
    def wall_point(self) -> np.ndarray:
        return self.corridor.point(self.s, self.side * self.corridor.half_width)

    @property
    def centre(self) -> np.ndarray:
        gap = 0.0 if self.kind in ON_WALL else WALL_GAP_M
        return self.wall_point + self.normal * (gap + self.shape.depth / 2.0)

    def footprint(self) -> Polygon:
        n = self.normal
        yaw = math.atan2(-n[0], n[1])
        c = self.centre
        return footprint(c[0], c[1], yaw, self.shape.length / 2.0, self.shape.depth / 2.0)


def _front(item: Mounted, margin: float, depth: float) -> Polygon:
    """The floor in front of a wall item: ``margin`` beyond either end, ``depth`` out."""
    c, n = np.asarray(item.centre, float), np.asarray(item.normal, float)
    t = np.array([-n[1], n[0]]) * (item.width / 2.0 + margin)
    back = c - n * 0.05
    return Polygon([back - t, back + t, back + t + n * depth, back - t + n * depth])


class ClutterPlan:
    """Where clutter may stand in ``world`` (its walls, doors, signs and landmarks built)."""

    def __init__(self, world: SceneWorld) -> None:
        b = world.building
        self.world = world
        self.corridors = [c for c in corridors(b) if c.length > MIN_CORRIDOR_M]
        self.floor = world.floor_space()
        shapely.prepare(self.floor)
        self.centre_lines = MultiLineString([LineString([c.a, c.b]) for c in self.corridors])
        keep = [Point(d.centre).buffer(SUCCESS_RADIUS_M) for d in world.doors.values()]
        keep += [
            Point(xy).buffer(hw * math.sqrt(2.0) + JUNCTION_CLEAR_M)
            for xy, hw in junction_points(b)
        ]
        across = 2.0 * max(c.half_width for c in self.corridors)
        for lm in world.landmarks.values():
            if lm.z[0] < 0.5:  # stands on the floor: an elevator, stairs, a desk
                keep.append(_front(lm, LANDMARK_CLEAR_M, across))
        for fd in world.fire_doors.values():  # where its leaves swing and lie held open
            line = LineString(fd.line)
            keep.append(line.buffer(line.length / 2.0))
        self.keep_out = shapely.union_all(keep)
        shapely.prepare(self.keep_out)
        self.signs = self._sign_sites()
        self.sign_fronts = shapely.union_all(
            [_front(it, 0.1, SIGN_FRONT_M) for it, _, _, _ in self.signs.values()]
        )
        shapely.prepare(self.sign_fronts)
        weights = KIND_WEIGHTS.get(b.kind.lower(), DEFAULT_WEIGHTS)
        self.kinds = [k for k in BUILDERS if weights.get(k, 0) > 0]
        w = np.array([weights[k] for k in self.kinds], float)
        self.weights = w / w.sum()

    def _on_side(self, it: Mounted) -> tuple[Corridor, float, int] | None:
        """The corridor whose side wall ``it`` hangs on, ``s`` along it and the side."""
        for c in self.corridors:
            s, lat = c.local(it.centre)
            facing = float(np.asarray(it.normal) @ c.left) * np.sign(lat)  # -1: inwards
            on_wall = abs(abs(lat) - c.half_width) < 0.1 and facing < -0.9
            if on_wall and -0.05 <= s <= c.length + 0.05:
                return c, s, 1 if lat > 0 else -1
        return None

    def _sign_sites(self) -> dict[str, tuple[Mounted, Corridor, float, int]]:
        """Every sign plate on a corridor's side wall that an item may stand before:
        label -> (plate, corridor, s, away): ``away`` (+-1 along s, 0 if none is near)
        points from the nearest door beside it. A plate wholly within a door's approach (on or
        above the door) is left out: an item before it would stand where the approach stays
        clear."""
        w = self.world
        plates = [*w.signs.values(), *w.landmark_signs.values()]
        plates += [lm for lm in w.landmarks.values() if lm.z[0] >= 0.5]  # plain plates
        doors = [d for d in map(self._on_side, w.doors.values()) if d is not None]
        door_xy = np.array([d.centre for d in w.doors.values()]).reshape(-1, 2)
        out = {}
        for it in plates:
            at = self._on_side(it)
            if at is None:
                continue
            gaps = np.linalg.norm(door_xy - np.asarray(it.centre), axis=1)
            if gaps.size and gaps.min() + it.width / 2.0 < SUCCESS_RADIUS_M:
                continue  # even its far edge is in a door's approach
            c, s, side = at
            near = [ds for dc, ds, dside in doors if dc is c and dside == side]
            near = [ds for ds in near if abs(ds - s) < 3.0]
            away = 0 if not near else (1 if s >= min(near, key=lambda ds: abs(ds - s)) else -1)
            out[it.label + "/" + it.kind] = (it, c, s, away)
        return out

    # -- candidates ------------------------------------------------------------------------

    def _shape(self, rng: np.random.Generator, floor_only: bool = False) -> tuple[str, Shape]:
        kinds, p = self.kinds, self.weights
        if floor_only:
            keep = [i for i, k in enumerate(kinds) if k not in ON_WALL]
            kinds = [kinds[i] for i in keep]
            p = p[keep] / p[keep].sum()
        kind = kinds[int(rng.choice(len(kinds), p=p))]
        return kind, BUILDERS[kind](rng)

    def candidate(self, rng: np.random.Generator) -> _Site | None:
        """A random item somewhere along a random wall (corridors weighted by length)."""
        lengths = np.array([c.length for c in self.corridors])
        c = self.corridors[int(rng.choice(len(lengths), p=lengths / lengths.sum()))]
        side = 1 if rng.random() < 0.5 else -1
        kind, shape = self._shape(rng)
        if shape.length >= c.length:
            return None
        s = float(rng.uniform(shape.length / 2.0, c.length - shape.length / 2.0))
        return _Site(c, side, s, shape, kind)

    def candidate_before_sign(self, rng: np.random.Generator) -> tuple[_Site, str] | None:
        """A random floor item partly in front of a random sign plate, tall enough to hide
        some of it."""
        if not self.signs:
            return None
        keys = sorted(self.signs)
        key = keys[int(rng.integers(len(keys)))]
        plate, c, s_plate, away = self.signs[key]
        for _ in range(TALL_TRIES):
            kind, shape = self._shape(rng, floor_only=True)
            if shape.top >= plate.z[0] + 0.1:
                break
        else:
            return None
        span = (shape.length + plate.width) / 2.0
        # Shifted along the wall, away from the door beside the plate (its approach is clear).
        shift = float(rng.uniform(0.0, 1.0)) if away else float(rng.uniform(-1.0, 1.0))
        s = s_plate + (away or 1) * shift * span * SIGN_COVER
        side = 1 if c.local(plate.centre)[1] > 0 else -1
        return _Site(c, side, s, shape, kind), plate.label

    # -- rules -----------------------------------------------------------------------------

    def allows(self, site: _Site, placed: list[ClutterItem], before_sign: bool) -> bool:
        """Whether ``site`` keeps to every rule of the module docstring."""
        c, shape = site.corridor, site.shape
        half = shape.length / 2.0
        if site.s - half < 0.0 or site.s + half > c.length:
            return False
        fp = site.footprint()
        if not self.floor.contains(fp.buffer(-0.005)):
            return False
        # A wall behind it all along (not the opening of a side corridor).
        t = c.along
        back = site.wall_point - site.normal * 0.05
        behind = [back + t * k for k in (-half + 0.05, 0.0, half - 0.05)]
        if shapely.contains_xy(self.floor, *np.array(behind).T).any():
            return False
        if self.keep_out.intersects(fp):
            return False
        if not before_sign and self.sign_fronts.intersects(fp):
            return False
        on_wall = site.kind in ON_WALL
        if not on_wall:
            if fp.distance(self.centre_lines) < CENTRE_BAND_M:
                return False
            if 2.0 * c.half_width - shape.depth - WALL_GAP_M < PASSAGE_M:
                return False
        for other in placed:
            if other.corridor == c.index and other.side != site.side and not on_wall:
                if other.kind in ON_WALL:
                    continue
                overlap = min(site.s + half, other.s + other.length / 2.0) - max(
                    site.s - half, other.s - other.length / 2.0
                )
                width = 2.0 * c.half_width - shape.depth - other.depth - 2 * WALL_GAP_M
                if overlap > -PASSAGE_M and width < PASSAGE_M:
                    return False
            elif fp.distance(other.footprint) < ITEM_GAP_M:
                return False
        return True


def add_item(world: SceneWorld, kind: str, shape: Shape, centre, normal) -> int:
    """Build one item of ``shape`` with its footprint centred at ``centre``, its back to the
    wall whose inward normal is ``normal``: a solid body labelled ``obstacle`` whose
    footprint counts in ``obstacle_footprints``."""
    yaw = math.atan2(-normal[0], normal[1])
    half = (shape.length / 2.0, shape.depth / 2.0, (shape.top - shape.bottom) / 2.0)
    with world.lock:
        body = compound_body(
            world.client,
            shape.parts,
            (float(centre[0]), float(centre[1])),
            yaw,
            Envelope(half=half, bottom=shape.bottom),
        )
    fp = footprint(float(centre[0]), float(centre[1]), yaw, half[0], half[1])
    return world.register(body, OBSTACLE_LABEL, solid=True, footprint=fp, bottom=shape.bottom)


def place_clutter(world: SceneWorld) -> list[ClutterItem]:
    """Place the config's clutter in ``world`` (nothing, and nothing drawn, when its
    density is 0); the items placed, in order. Fewer are placed where the rules leave too
    little wall (logged)."""
    scene = world.scene
    if scene.clutter_per_10m <= 0.0:
        return []
    if not any(c.length > MIN_CORRIDOR_M for c in corridors(world.building)):
        return []
    rng = world.rng("clutter")
    plan = ClutterPlan(world)
    walls = world.walls[: world.annotated_walls]  # the corridors' walls (not grid hangers)
    expected = sum(w.length for w in walls) * scene.clutter_per_10m / 10.0
    n = int(expected) + int(rng.random() < expected - int(expected))
    n_before = int(round(n * scene.clutter_before_signs))
    placed: list[ClutterItem] = []
    for i in range(n):
        for attempt in range(TRIES_PER_ITEM):
            before = ""
            if i < n_before and attempt < BEFORE_SIGN_TRIES:
                found = plan.candidate_before_sign(rng)
                site, before = found if found is not None else (None, "")
            else:
                site = plan.candidate(rng)
            if site is None or not plan.allows(site, placed, bool(before)):
                continue
            c = site.centre
            body = add_item(world, site.kind, site.shape, c, site.normal)
            placed.append(
                ClutterItem(
                    site.kind,
                    body,
                    (float(c[0]), float(c[1])),
                    (float(site.normal[0]), float(site.normal[1])),
                    site.shape.length,
                    site.shape.depth,
                    site.shape.bottom,
                    site.shape.top,
                    site.corridor.index,
                    site.side,
                    site.s,
                    before,
                )
            )
            break
    if len(placed) < n:
        log.info("%s: placed %d of %d clutter items", world.building.name, len(placed), n)
    return placed
