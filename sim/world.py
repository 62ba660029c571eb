"""Build a pybullet world from a Building: floor, ceiling, corridor walls, doors, signs, landmarks.

The free space is the union of the corridor rectangles (each corridor buffered by half
its width with square ends, so dead ends close half a width beyond the end waypoint
and corners are square); walls are thin boxes extruded outwards from every edge of
that polygon, so junctions stay open. Doors, sign plates and landmarks are snapped to
the nearest wall (with walls from a ros_map grid, then moved onto the grid's real
wall). Every body carries a semantic label ("floor", "wall", "ceiling", "door:<room>",
"sign:<room>", "landmark:<id>", "obstacle", "robot", "person"); segmentation images map
to label ids through ``SimWorld.labels``. What fills the corridors beyond the building
file (signage styles, door states, clutter, walking people) is built by
``pmnav_bt.sim.scene``.

pybullet is not thread-safe: every pybullet call goes through ``SimWorld.lock``.
"""

from __future__ import annotations

import logging
import math
import os
import tempfile
import threading
from collections.abc import Collection
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

from pmnav_bt.config import WorldConfig
from pmnav_bt.errors import PmNavError
from pmnav_bt.map.building import Building, Landmark, WaypointKind
from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.floorplan import DOOR_WIDTH_M
from pmnav_bt.map.free_space import free_space_polygon, free_space_rings
from pmnav_bt.map.landmark_kinds import (
    DESK,
    DESK_DEPTH_M,
    DESK_LENGTH_M,
    ELEVATOR,
    ELEVATOR_FRAME_M,
    ELEVATOR_PANEL_M,
    ELEVATOR_WIDTH_M,
    PLATE_BACKING_M,
    STAIRS,
    STAIRS_DEPTH_M,
    STAIRS_LENGTH_M,
    landmark_shape,
)
from pmnav_bt.map.wall_items import (
    DOOR_FRAME_M,
    WallPlacer,
    WallSegment,
    annotated_walls,
    door_item,
    landmark_item,
)
from pmnav_bt.seams import (
    CAMERA_HEIGHT_M,
    CEILING_LABEL,
    FLOOR_LABEL,
    OBSTACLE_LABEL,
    WALL_LABEL,
    Pose2D,
    door_label,
    landmark_label,
    sign_label,
)
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.scene import scene_rng
from pmnav_bt.sim.scene.appearance import WALL_THICKNESS, appearance_of
from pmnav_bt.sim.scene.clutter import ClutterItem, place_clutter
from pmnav_bt.sim.scene.doors import DoorLeaf, DoorState, build_leaf, door_states
from pmnav_bt.sim.scene.fire_doors import FireDoor, build_fire_doors
from pmnav_bt.sim.scene.lifts import Cabin, build_cabin, doorway_cut, doorway_s
from pmnav_bt.sim.scene.people import Crowd, populate
from pmnav_bt.sim.scene.plates import make_line_plate
from pmnav_bt.sim.scene.sign_mounting import SIGN_DEPTH, SIGN_GAP, mount_signage
from pmnav_bt.sim.scene.signage import resolve_signage
from pmnav_bt.sim.textures import SignTexture, make_sign, write_png
from pmnav_bt.sim.wall_mounting import GridMounts, MovedItem, grid_clearings, moved_items, summary

log = logging.getLogger(__name__)


class SimError(PmNavError):
    """The simulator cannot do what was asked (no display for the GUI, a bad obstacle ...)."""


# -- labels ------------------------------------------------------------------------------

BACKGROUND = "background"
FLOOR = FLOOR_LABEL
WALL = WALL_LABEL
CEILING = CEILING_LABEL
OBSTACLE = OBSTACLE_LABEL
ROBOT = "robot"
FIXED_LABELS = (BACKGROUND, FLOOR, WALL, CEILING, OBSTACLE, ROBOT)  # ids 0..5
WALL_SOURCES = ("corridors", "grid")  # what the simulator builds its walls from

# door_label / sign_label / landmark_label: spelled once, in pmnav_bt.seams.


# -- appearance and sizes (metres, RGBA) -------------------------------------------------

PLATE_RGBA = (0.15, 0.15, 0.15, 1.0)
METAL_RGBA = (0.70, 0.73, 0.78, 1.0)
STEEL_DARK_RGBA = (0.35, 0.37, 0.40, 1.0)
STEP_RGBA = ((0.62, 0.62, 0.60, 1.0), (0.50, 0.50, 0.48, 1.0))
DESK_RGBA = (0.40, 0.27, 0.18, 1.0)
COUNTER_RGBA = (0.92, 0.92, 0.88, 1.0)
OBSTACLE_RGBA = (0.95, 0.45, 0.10, 1.0)

SKIRTING_HEIGHT = 0.10
DOOR_HEIGHT = 2.1
FRAME_DEPTH = 0.04  # how far door frames stand out of the wall
PANEL_DEPTH = 0.02
SIGN_CENTRE_Z = CAMERA_HEIGHT_M  # sign plates are centred at camera height
ELEVATOR_HEIGHT = 2.2
STAIRS_STEPS = 6
STAIRS_RISE = 0.17
DESK_HEIGHT = 1.0


@dataclass(frozen=True)
class WallItem:
    """Something mounted on a corridor wall: a door, a sign plate or a landmark."""

    id: str  # room or landmark id
    kind: str  # "door", "sign", or the landmark's kind
    label: str
    centre: tuple[float, float]  # on the wall surface, map frame
    normal: tuple[float, float]  # unit, from the wall into the corridor
    width: float  # along the wall
    z: tuple[float, float]  # bottom and top heights
    text: str = ""

    @property
    def facing_yaw(self) -> float:
        """Heading of a viewer looking straight at the item (along -normal)."""
        return math.atan2(-self.normal[1], -self.normal[0])

    def viewpoint(self, distance: float) -> Pose2D:
        """A pose ``distance`` metres out from the wall, facing the item."""
        x = self.centre[0] + distance * self.normal[0]
        y = self.centre[1] + distance * self.normal[1]
        return Pose2D(float(x), float(y), self.facing_yaw)


@dataclass(frozen=True)
class RayHit:
    """First hit of a ray: the body, its label, distance from the start, point and normal."""

    body: int
    label: str
    distance: float
    point: tuple[float, float, float]
    normal: tuple[float, float, float]


def _xy(v) -> tuple[float, float]:
    return float(v[0]), float(v[1])


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


class SimWorld:
    """A pybullet world built from a Building, with its own physics client and lock.

    Parameters: ``building`` (a Building, a built-in name or a path), ``gui`` (use
    p.GUI; needs a display), ``ceiling`` (add a ceiling at the wall height), ``walls``:
    ``corridors`` builds the walls from the annotated corridor rectangles, ``grid``
    from the occupied cells of the building's ros_map floor plan (rooms and open areas
    included; doors, signs and landmarks are hung on the grid's real walls, and
    ``moved_items`` says how far each moved, ``sim.wall_mounting``);
    ``base_dir`` is the folder the floor plan path is relative to (default: the
    building file's folder). ``scene`` (the config's ``world`` section; default: the clean
    preset) says what fills the building beyond its file, drawn from the episode's
    ``seed`` (``pmnav_bt.sim.scene``). ``lifts``: the lift landmarks (ids) with a cabin
    behind their doors (``sim/scene/lifts.py``; ``cabins``): a level of a site, whose
    lifts the robot rides (``pmnav_bt.sim.lift``).
    """

    def __init__(
        self,
        building: Building | str | Path,
        *,
        gui: bool = False,
        ceiling: bool = True,
        walls: str = "corridors",
        base_dir: str | Path | None = None,
        scene: WorldConfig | None = None,
        seed: int = 0,
        lifts: Collection[str] = (),
    ) -> None:
        if walls not in WALL_SOURCES:
            raise SimError(f"walls {walls!r}: choose {' or '.join(WALL_SOURCES)}")
        if not isinstance(building, Building):
            base_dir = base_dir if base_dir is not None else resolve_building_path(building).parent
            building = load_building(building)
        self.building = building
        self.wall_source = walls
        self.scene = scene if scene is not None else WorldConfig()
        self.seed = int(seed)
        self.lift_lobbies = frozenset(lifts)
        lift_ids = {lm.id for lm in building.landmarks if landmark_shape(lm.kind) is ELEVATOR}
        unknown = sorted(self.lift_lobbies - lift_ids)
        if unknown:
            raise SimError(f"{building.name}: no lift landmark {unknown[0]!r} for a cabin")
        self.cabins: dict[str, Cabin] = {}  # lift landmark id -> its cabin (``lifts``)
        self._elevator_leaves: dict[str, list[int]] = {}
        self.appearance = appearance_of(self)
        self._grid_plan = self._load_grid_plan(base_dir) if walls == "grid" else None
        self._mounts = GridMounts(self._grid_plan) if self._grid_plan is not None else None
        self.moved_items: list[MovedItem] = []  # grid walls: what was hung on the real wall
        self.lock = threading.RLock()
        self.labels: dict[int, str] = {}
        self._label_ids: dict[str, int] = {}
        for name in FIXED_LABELS:
            self.label_id(name)
        self._body_label: dict[int, int] = {}
        self._lut: np.ndarray | None = None
        self._solid: set[int] = set()
        self._boxes: dict[int, tuple[Polygon, float]] = {}  # solid body -> footprint, bottom z
        self._probe_shapes: dict[tuple[float, float], int] = {}
        self._where: dict[str, tuple[int, float]] = {}  # label -> (wall, s) of the main item
        self._tmp = tempfile.TemporaryDirectory(prefix="pmnav_sim_")
        self.walls: list[WallSegment] = []
        self._placer = WallPlacer(self.walls)  # what hangs where on them (_build_walls)
        self.annotated_walls = 0  # walls[:annotated_walls] bound the free space; the rest
        # are the grid's real walls that items hang on (walls="grid", ``_mount``)
        self.doors: dict[str, WallItem] = {}
        self.door_states: dict[str, DoorState] = {}
        self.signs: dict[str, WallItem] = {}
        self.landmarks: dict[str, WallItem] = {}
        self.landmark_signs: dict[str, WallItem] = {}
        self.fire_doors: dict[str, FireDoor] = {}  # across corridors, not on walls
        self.directional_signs: dict[str, WallItem] = {}  # by index in the file, "0", "1" ...
        self.obstacles: dict[int, tuple[float, float, float]] = {}
        self.clutter: list[ClutterItem] = []
        self.people = Crowd(self, [], [])
        if gui:
            if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
                raise SimError(
                    "--gui needs a display, but DISPLAY is not set; "
                    "run without --gui to write images only"
                )
            self.client = p.connect(p.GUI)
        else:
            self.client = p.connect(p.DIRECT)
        if self.client < 0:
            raise SimError("could not start a pybullet physics client")
        self._ceiling_wanted = ceiling
        self.free_space = free_space_polygon(self.building)
        try:
            with self.lock:
                self._build()
        except BaseException:
            self.close()
            raise

    def rng(self, part: str) -> np.random.Generator:
        """The random stream of one part of this world's scene (``scene_rng``)."""
        return scene_rng(self.seed, self.building.name, part)

    # -- lifecycle ------------------------------------------------------------------------

    def close(self) -> None:
        """Disconnect the physics client and delete the texture files."""
        with self.lock:
            if self.client >= 0 and p.isConnected(physicsClientId=self.client):
                p.disconnect(physicsClientId=self.client)
            self.client = -1
        self._tmp.cleanup()

    def __enter__(self) -> SimWorld:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- labels ---------------------------------------------------------------------------

    def label_id(self, label: str) -> int:
        """The id of a label (registered on first use)."""
        if label not in self._label_ids:
            i = len(self._label_ids)
            self._label_ids[label] = i
            self.labels[i] = label
        return self._label_ids[label]

    def label_of(self, body: int) -> str:
        """The label of a pybullet body id (BACKGROUND for -1 or unknown)."""
        return self.labels[self._body_label.get(body, 0)]

    def bodies_with_label(self, label: str) -> list[int]:
        lid = self._label_ids.get(label, -1)
        return [b for b, i in self._body_label.items() if i == lid]

    def segmentation_to_labels(self, seg: np.ndarray) -> np.ndarray:
        """Map a pybullet segmentation image (body ids, -1 = nothing) to label ids."""
        if self._lut is None:
            n = max(self._body_label, default=0) + 2
            lut = np.zeros(n, np.int32)
            for body, lid in self._body_label.items():
                lut[body + 1] = lid
            self._lut = lut
        seg = np.asarray(seg, np.int64)
        out = np.zeros(seg.shape, np.int32)
        ok = (seg >= -1) & (seg < len(self._lut) - 1)
        out[ok] = self._lut[seg[ok] + 1]
        return out

    # -- bodies ---------------------------------------------------------------------------

    def register(
        self,
        body: int,
        label: str,
        solid: bool = False,
        footprint: Polygon | None = None,
        bottom: float = 0.0,
    ) -> int:
        """Give a body created with this world's client a label; ``solid`` ones block the
        robot, and a solid one with a floor ``footprint`` (its lowest point ``bottom`` m up)
        counts in ``obstacle_footprints``."""
        self._body_label[body] = self.label_id(label)
        self._lut = None
        if solid:
            self._solid.add(body)
            if footprint is not None:
                self._boxes[body] = (footprint, float(bottom))
        return body

    def add_box(
        self,
        centre: tuple[float, float, float],
        half_extents: tuple[float, float, float],
        yaw: float,
        rgba: tuple[float, ...],
        label: str,
        *,
        solid: bool = True,
        collision: bool | None = None,
    ) -> int:
        """A static box; ``solid`` bodies block the robot, ``collision`` ones block rays."""
        collision = solid if collision is None else collision
        c = self.client
        with self.lock:
            vis = p.createVisualShape(
                p.GEOM_BOX, halfExtents=half_extents, rgbaColor=rgba, physicsClientId=c
            )
            col = (
                p.createCollisionShape(p.GEOM_BOX, halfExtents=half_extents, physicsClientId=c)
                if collision
                else -1
            )
            q = p.getQuaternionFromEuler((0.0, 0.0, yaw))
            body = p.createMultiBody(0.0, col, vis, centre, q, physicsClientId=c)
        if solid:
            hx, hy = half_extents[0], half_extents[1]
            corners = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
            cy_, sy_ = math.cos(yaw), math.sin(yaw)
            footprint = Polygon(
                [(centre[0] + cy_ * u - sy_ * v, centre[1] + sy_ * u + cy_ * v) for u, v in corners]
            )
            self._boxes[body] = (footprint, float(centre[2] - half_extents[2]))
        return self.register(body, label, solid)

    def floor_space(self) -> Polygon | MultiPolygon:
        """Where the floor is open, walls aside: the corridor polygon, or with grid walls
        the grid's extent less the footprints of the solid wall boxes."""
        if self._grid_plan is None:
            return self.free_space
        x0, y0, x1, y1 = self.bounds()
        wall = self.label_id(WALL)
        boxes = [
            fp
            for body, (fp, _) in self._boxes.items()
            if body in self._solid and self._body_label.get(body) == wall
        ]
        return shapely.box(x0, y0, x1, y1).difference(shapely.union_all(boxes))

    def obstacle_footprints(self, below: float) -> list[Polygon]:
        """Floor footprints of the solid boxes other than walls whose bottom is under
        ``below`` metres (landmarks such as desks and stairs, added obstacles)."""
        wall = self.label_id(WALL)
        return [
            fp
            for body, (fp, z0) in self._boxes.items()
            if z0 < below and body in self._solid and self._body_label.get(body) != wall
        ]

    def _add_textured_quad(
        self,
        centre: np.ndarray,
        normal: np.ndarray,
        width: float,
        height: float,
        image: np.ndarray,
        label: str,
    ) -> int:
        """A flat quad facing ``normal`` (2D), showing ``image`` upright and unmirrored."""
        left = np.array([normal[1], -normal[0], 0.0]) * (width / 2.0)  # viewer's left
        up = np.array([0.0, 0.0, height / 2.0])
        verts = [left - up, -left - up, -left + up, left + up]
        uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        # Normals point at the light, so plates are evenly lit from every side (as bright as
        # the light's level makes a face turned to it).
        normals = [list(self.appearance.light.direction)] * 4
        path = write_png(image, Path(self._tmp.name) / f"tex{len(self._body_label)}.png")
        c = self.client
        with self.lock:
            vis = p.createVisualShape(
                p.GEOM_MESH,
                vertices=[v.tolist() for v in verts],
                indices=[0, 1, 2, 0, 2, 3],
                uvs=uvs,
                normals=normals,
                rgbaColor=(1.0, 1.0, 1.0, 1.0),
                physicsClientId=c,
            )
            body = p.createMultiBody(0.0, -1, vis, centre.tolist(), physicsClientId=c)
            tex = p.loadTexture(str(path), physicsClientId=c)
            p.changeVisualShape(body, -1, textureUniqueId=tex, physicsClientId=c)
        return self.register(body, label, solid=False)

    def add_obstacle(self, x: float, y: float, size: float, height: float = 1.0) -> int:
        """A square box obstacle (side ``size``) standing on the floor at (x, y); its body id."""
        if not (size > 0 and height > 0):
            raise SimError(f"obstacle size and height must be positive (got {size}, {height})")
        body = self.add_box(
            (x, y, height / 2.0),
            (size / 2.0, size / 2.0, height / 2.0),
            0.0,
            OBSTACLE_RGBA,
            OBSTACLE,
        )
        self.obstacles[body] = (float(x), float(y), float(size))
        return body

    def remove_obstacle(self, body: int) -> None:
        with self.lock:
            if body not in self.obstacles:
                raise SimError(f"body {body} is not an obstacle of this world")
            p.removeBody(body, physicsClientId=self.client)
            del self.obstacles[body]
            self._solid.discard(body)
            self._boxes.pop(body, None)
            self._body_label.pop(body, None)
            self._lut = None

    # -- queries --------------------------------------------------------------------------

    def ray(self, start: tuple[float, ...], end: tuple[float, ...]) -> RayHit | None:
        """The first body a ray from ``start`` to ``end`` (3D, metres) hits, or None."""
        with self.lock:
            hit = p.rayTest(start, end, physicsClientId=self.client)[0]
        body, frac = hit[0], hit[2]
        if body < 0:
            return None
        length = math.dist(start, end)
        return RayHit(body, self.label_of(body), frac * length, tuple(hit[3]), tuple(hit[4]))

    def _probe(self, radius: float, height: float) -> int:
        key = (round(radius, 4), round(height, 4))
        if key not in self._probe_shapes:
            with self.lock:
                self._probe_shapes[key] = p.createCollisionShape(
                    p.GEOM_CYLINDER, radius=radius, height=height, physicsClientId=self.client
                )
        return self._probe_shapes[key]

    def clearance(
        self, x: float, y: float, radius: float, height: float = 1.7, margin: float = 0.05
    ) -> float:
        """Signed distance from an upright cylinder at (x, y) to the nearest solid body.

        Negative means penetration; ``margin`` is returned when nothing is that close.
        The cylinder stands 2 cm above the floor, so the floor never counts.
        """
        z = 0.02 + height / 2.0
        r = radius + margin + 0.05
        best = min(margin, self.people.clearance(x, y, radius))  # upright cylinders too
        with self.lock:
            shape = self._probe(radius, height)
            found = p.getOverlappingObjects(
                (x - r, y - r, 0.0), (x + r, y + r, height + 0.1), physicsClientId=self.client
            )
            if not found:
                return best
            for body in {b for b, _ in found}:
                if body not in self._solid:
                    continue
                pts = p.getClosestPoints(
                    -1,
                    body,
                    margin,
                    collisionShapeA=shape,
                    collisionShapePositionA=(x, y, z),
                    collisionShapeOrientationA=(0.0, 0.0, 0.0, 1.0),
                    physicsClientId=self.client,
                )
                for pt in pts:
                    best = min(best, pt[8])
        return best

    def start_pose(self) -> Pose2D:
        """The first start waypoint, facing along its corridor."""
        b = self.building
        starts = [w for w in b.waypoints if w.kind == WaypointKind.START] or list(b.waypoints)
        w = starts[0]
        for e in b.edges:
            if w.id in (e.a, e.b):
                other = b.waypoint(e.b if e.a == w.id else e.a)
                yaw = math.atan2(other.pos[1] - w.pos[1], other.pos[0] - w.pos[0])
                return Pose2D(float(w.pos[0]), float(w.pos[1]), yaw)
        return Pose2D(float(w.pos[0]), float(w.pos[1]), 0.0)

    def bounds(self, margin: float = 0.0) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the free space (and grid walls), grown by ``margin``."""
        x0, y0, x1, y1 = self.free_space.bounds
        if self._grid_plan is not None:
            c = self._grid_plan.corners_world()
            x0, y0 = min(x0, c[:, 0].min()), min(y0, c[:, 1].min())
            x1, y1 = max(x1, c[:, 0].max()), max(y1, c[:, 1].max())
        return x0 - margin, y0 - margin, x1 + margin, y1 + margin

    def _load_grid_plan(self, base_dir: str | Path | None):
        from pmnav_bt.map.floorplan import load_floor_plan

        fp = self.building.floor_plan
        if fp is None or fp.ros_map is None:
            raise SimError(
                f"{self.building.name}: walls from the grid need a floor_plan with ros_map "
                "(a map_server map); use walls 'corridors' or add the map"
            )
        if base_dir is None and not Path(fp.ros_map).is_absolute():
            raise SimError(
                f"{self.building.name}: walls from the grid need the building file's folder "
                "to find floor_plan.ros_map; pass the file's path"
            )
        return load_floor_plan(self.building, base_dir or ".")

    # -- building ------------------------------------------------------------------------

    def _build(self) -> None:
        b = self.building
        c = self.client
        p.setGravity(0, 0, 0, physicsClientId=c)
        x0, y0, x1, y1 = self.bounds(margin=3.0)
        cx, cy = (x0 + x1) / 2.0, (y0 + y1) / 2.0
        hx, hy = (x1 - x0) / 2.0, (y1 - y0) / 2.0
        self.add_box(
            (cx, cy, -0.05),
            (hx, hy, 0.05),
            0.0,
            self.appearance.floor,
            FLOOR,
            solid=False,
            collision=True,
        )
        if self._ceiling_wanted:
            self.add_box(
                (cx, cy, b.wall_height + 0.05),
                (hx, hy, 0.05),
                0.0,
                self.appearance.ceiling,
                CEILING,
                solid=False,
                collision=True,
            )
        self._build_walls()
        for room in b.rooms:
            self.label_id(door_label(room.id))
            self.label_id(sign_label(room.id))
        for lm in b.landmarks:
            self.label_id(landmark_label(lm.id))
        self.door_states = door_states([r.id for r in b.rooms], self.scene, self.rng("doors"))
        self._signage = resolve_signage(b, self.scene.signage, self.rng("signage"))
        for room in b.rooms:
            self._build_door(room.id, room.door)
        for lm in b.landmarks:
            self._build_landmark(lm)
        self._build_cabins()
        self._build_signage()
        if self._grid_plan is not None:
            self._build_grid_walls()
        self.fire_doors = build_fire_doors(self)
        self.clutter = place_clutter(self)
        self.people = populate(self)
        self.appearance.dress(self)  # last: it dresses what the rest built

    def _build_grid_walls(self) -> None:
        """Walls from the grid's cells, with each door's opening cut and the cells just in
        front of every item kept free (items hang on the real walls: ``_mount``)."""
        from pmnav_bt.sim.grid_walls import grid_wall_boxes

        h = self.building.wall_height
        self.moved_items = moved_items(self)
        log.info("%s: %s", self.building.name, summary(self.moved_items))
        for bx in grid_wall_boxes(self._grid_plan, clear=grid_clearings(self)):
            (cx, cy), (hx, hy) = bx.centre, bx.half
            self.add_box((cx, cy, h / 2.0), (hx, hy, h / 2.0), 0.0, self.appearance.wall, WALL)

    def _build_walls(self) -> None:
        h = self.building.wall_height
        t = WALL_THICKNESS
        grid = self.wall_source == "grid"
        self.walls.extend(annotated_walls(self.free_space))
        self._placer = WallPlacer(self.walls)
        doorways: dict[tuple, list[float]] = {}  # a lift's doorway through its wall
        for lm in self.building.landmarks:
            if lm.id in self.lift_lobbies:
                wi, s_wall = self._placer.nearest(lm.pos)
                w = self.walls[wi]
                doorways.setdefault((w.a, w.b), []).append(doorway_s(s_wall))
        for ring in free_space_rings(self.free_space):
            n = len(ring)
            pts = [np.asarray(q, float) for q in ring]
            for i in range(n):
                a, b = pts[i], pts[(i + 1) % n]
                prev, nxt = pts[i - 1], pts[(i + 2) % n]
                d = b - a
                length = float(np.linalg.norm(d))
                if length < 1e-6:
                    continue
                tan = d / length
                inward = np.array([-tan[1], tan[0]])  # free space is on the left
                # Extend past convex corners (seen from the free space) to close them.
                ext_a = t if _cross(a - prev, d) > 1e-9 else 0.0
                ext_b = t if _cross(d, nxt - b) > 1e-9 else 0.0
                mid = (a + b) / 2.0 + tan * (ext_b - ext_a) / 2.0 - inward * t / 2.0
                yaw = math.atan2(tan[1], tan[0])
                half_len = length / 2.0 + (ext_a + ext_b) / 2.0
                if grid:  # the annotated walls only carry the doors and signs
                    continue
                opened = doorways.get((ring[i], ring[(i + 1) % n]))
                if opened:
                    self._wall_pieces(a, tan, inward, doorway_cut(length, opened, ext_a, ext_b))
                    continue
                self.add_box(
                    (mid[0], mid[1], h / 2.0),
                    (half_len, t / 2.0, h / 2.0),
                    yaw,
                    self.appearance.wall,
                    WALL,
                )
                sk = (a + b) / 2.0 + inward * 0.005
                self.add_box(
                    (sk[0], sk[1], SKIRTING_HEIGHT / 2.0),
                    (length / 2.0, 0.005, SKIRTING_HEIGHT / 2.0),
                    yaw,
                    self.appearance.skirting,
                    WALL,
                    solid=False,
                    collision=False,
                )
        self.annotated_walls = len(self.walls)

    def _wall_pieces(self, a, tan, inward, pieces: list[tuple[float, float]]) -> None:
        """A wall (with its skirting) from ``a`` along ``tan`` as the ``pieces`` (from, to
        metres along it) left round a lift's doorway (``sim/scene/lifts.py``)."""
        h, t = self.building.wall_height, WALL_THICKNESS
        yaw = math.atan2(tan[1], tan[0])
        for lo, hi in pieces:
            mid = a + tan * (lo + hi) / 2.0
            wall = mid - inward * t / 2.0
            self.add_box(
                (wall[0], wall[1], h / 2.0), ((hi - lo) / 2.0, t / 2.0, h / 2.0), yaw,
                self.appearance.wall, WALL,
            )  # fmt: skip
            sk = mid + inward * 0.005
            self.add_box(
                (sk[0], sk[1], SKIRTING_HEIGHT / 2.0),
                ((hi - lo) / 2.0, 0.005, SKIRTING_HEIGHT / 2.0),
                yaw, self.appearance.skirting, WALL, solid=False, collision=False,
            )  # fmt: skip

    # -- placing things on walls ---------------------------------------------------------

    def _nearest_wall(self, pt: tuple[float, float]) -> tuple[int, float]:
        """Index of the wall segment nearest to ``pt`` and the distance along it."""
        return self._placer.nearest(pt)

    def _fits(self, wall: int, s0: float, s1: float) -> bool:
        return self._placer.fits(wall, s0, s1)

    def _occupy(self, wall: int, s: float, half: float) -> None:
        self._placer.occupy(wall, s, half)

    def _snap(
        self, what: str, pt: tuple[float, float], half: float, *, at_foot: bool = False
    ) -> tuple[int, float]:
        """Wall and position along it for an item ``2*half`` wide nearest to ``pt`` (with
        grid walls, the real wall behind that place: ``_mount``); what does not fit there
        is logged (``pmnav validate`` warns of the same, ``map.wall_items``). ``at_foot``:
        a lift, hung at its point's foot (``WallPlacer.place``)."""
        placed = self._placer.place(what, pt, half, at_foot=at_foot)
        for problem in placed.problems:
            log.warning("%s", problem)
        return self._mount(placed.wall, placed.s, half, pt)

    def _mount(
        self, wi: int, s: float, half: float, pt: tuple[float, float]
    ) -> tuple[int, float]:
        """Where the item at ``s`` on annotated wall ``wi`` (its file point ``pt``) hangs,
        a wall and the distance along it: with grid walls, on a wall segment of its own
        through the grid's real wall there, as long as that wall runs on straight
        (``GridMounts``), measured in the same ``s`` (shifted where the real wall starts
        before the annotated one) and sharing the annotated wall's occupied stretches;
        else on ``wi`` at ``s``."""
        if self._mounts is None:
            return wi, s
        w = self.walls[wi]
        a, b, normal, found, shift = self._mounts.real_wall(
            w.a, w.b, w.normal, s, half, at=pt
        )
        self.walls.append(WallSegment(a, b, normal))
        mounted = len(self.walls) - 1
        self._placer.share(mounted, wi, shift)
        self._mounts.record(mounted, wi, found, shift)
        return mounted, s + shift

    def _wall_box(
        self,
        wall: int,
        s: float,
        depth: float,
        width: float,
        z0: float,
        z1: float,
        rgba: tuple[float, ...],
        label: str,
        *,
        solid: bool = True,
        out: float = 0.0,
    ) -> int:
        """A box on a wall: ``width`` along it, standing ``depth`` out of it (from ``out``)."""
        w = self.walls[wall]
        n = np.asarray(w.normal)
        c = w.point(s) + n * (out + depth / 2.0)
        yaw = math.atan2(w.tangent[1], w.tangent[0])
        return self.add_box(
            (c[0], c[1], (z0 + z1) / 2.0),
            (width / 2.0, depth / 2.0, (z1 - z0) / 2.0),
            yaw,
            rgba,
            label,
            solid=solid,
        )

    def _item(
        self,
        ident: str,
        kind: str,
        label: str,
        wall: int,
        s: float,
        width: float,
        z: tuple[float, float],
        text: str = "",
    ) -> WallItem:
        w = self.walls[wall]
        c = w.point(s)
        self._where.setdefault(label, (wall, s))
        return WallItem(ident, kind, label, _xy(c), w.normal, float(width), z, text)

    def _build_door(self, room_id: str, pt: tuple[float, float]) -> None:
        label = door_label(room_id)
        total = DOOR_WIDTH_M + 2 * DOOR_FRAME_M
        wi, s = self._snap(door_item(room_id), pt, total / 2.0)
        fw, fd = DOOR_FRAME_M, FRAME_DEPTH
        look = self.appearance
        leaf = DoorLeaf(DOOR_WIDTH_M, DOOR_HEIGHT, PANEL_DEPTH, look.door, look.handle)
        build_leaf(partial(self._wall_box, wi), s, label, self.door_states[room_id], leaf)
        for side in (-1, 1):
            js = s + side * (DOOR_WIDTH_M + fw) / 2.0
            self._wall_box(wi, js, fd, fw, 0.0, DOOR_HEIGHT + fw, look.frame, label)
        self._wall_box(wi, s, fd, DOOR_WIDTH_M, DOOR_HEIGHT, DOOR_HEIGHT + fw, look.frame, label)
        self.doors[room_id] = self._item(
            room_id, "door", label, wi, s, total, (0.0, DOOR_HEIGHT + fw)
        )

    def _build_plate(
        self,
        ident: str,
        label: str,
        text: str,
        wall: int,
        s: float,
        z_centre: float,
        kind: str,
    ) -> WallItem:
        tex = self._plate_texture(text)
        w = self.walls[wall]
        n = np.asarray(w.normal)
        z0, z1 = z_centre - tex.height_m / 2.0, z_centre + tex.height_m / 2.0
        self._wall_box(
            wall, s, SIGN_DEPTH, tex.width_m + 0.02, z0 - 0.01, z1 + 0.01, PLATE_RGBA, label
        )
        centre = np.append(w.point(s) + n * (SIGN_DEPTH + 0.002), z_centre)
        self._add_textured_quad(centre, n, tex.width_m, tex.height_m, tex.image, label)
        return self._item(ident, kind, label, wall, s, tex.width_m + 0.02, (z0, z1), text)

    def _plate_beside(
        self, item: WallItem, wi: int, s_item: float, what: str, text: str
    ) -> tuple[int, float, float]:
        """Wall, position and height for the plate of ``text`` beside ``item`` (right, else
        left)."""
        half = (self._plate_texture(text).width_m + 0.02) / 2.0
        off = item.width / 2.0 + SIGN_GAP + half
        for s in (s_item - off, s_item + off):  # -s is the viewer's right
            if self._fits(wi, s - half, s + half):
                self._occupy(wi, s, half)
                return wi, s, SIGN_CENTRE_Z
        log.info("%s: no room beside it on the wall; the sign goes above it", what)
        return wi, s_item, item.z[1] + 0.35

    def _build_room_sign(self, room_id: str, text: str) -> None:
        door = self.doors[room_id]
        wi, s, z = self._plate_beside(
            door, *self._where[door.label], f"sign of {room_id}", text
        )
        self.signs[room_id] = self._build_plate(
            room_id, sign_label(room_id), text, wi, s, z, "sign"
        )

    def _plate_texture(self, text: str) -> SignTexture:
        """A landmark's plate: today's, or a one-line plate in the building's style."""
        if self._signage is None:
            return make_sign(text)
        return make_line_plate(text, self._signage.style)

    def _build_signage(self) -> None:
        """Room signs in the building's style (sim/scene/sign_mounting.py), or today's
        plates where the file has no signage section and the config draws none."""
        if self._signage is None:
            for room in self.building.rooms:
                self._build_room_sign(room.id, room.sign_text)
        else:
            mount_signage(self, self._signage, WallItem)

    def _build_landmark(self, lm: Landmark) -> None:
        shape = landmark_shape(lm.kind)
        if shape.across:
            return  # a fire door stands across its corridor (build_fire_doors), not on a wall
        label = landmark_label(lm.id)
        text = lm.sign_text
        if shape is ELEVATOR:
            item = self._build_elevator(lm, label)
        elif shape is STAIRS:
            item = self._build_stairs(lm, label)
        elif shape is DESK:
            item = self._build_desk(lm, label)
        else:
            half = (self._plate_texture(text).width_m + PLATE_BACKING_M) / 2.0
            wi, s = self._snap(landmark_item(lm.id), lm.pos, half)
            item = self._build_plate(lm.id, label, text, wi, s, SIGN_CENTRE_Z, lm.kind)
            self.landmarks[lm.id] = item
            return
        self.landmarks[lm.id] = item
        wi, s = self._where[label]
        if shape is ELEVATOR:
            wi, s, z = self._plate_beside(item, wi, s, f"sign of {lm.id}", text)
        else:  # above the steps or the desk, on the wall at camera height
            z = SIGN_CENTRE_Z
        self.landmark_signs[lm.id] = self._build_plate(lm.id, label, text, wi, s, z, "lmsign")

    def _build_elevator(self, lm: Landmark, label: str) -> WallItem:
        fw = ELEVATOR_FRAME_M
        total = ELEVATOR.span_m  # the doors, their frame and the call-button panel beside it
        wi, s = self._snap(landmark_item(lm.id), lm.pos, total / 2.0, at_foot=True)
        s_door = s + ELEVATOR_PANEL_M / 2.0  # the call panel sits on the viewer's right (-s)
        half = ELEVATOR_WIDTH_M / 4.0
        leaves = self._elevator_leaves.setdefault(lm.id, [])
        for side in (-1, 1):
            leaves.append(self._wall_box(
                wi,
                s_door + side * (half + 0.01),
                0.03,
                2 * half - 0.02,
                0.0,
                ELEVATOR_HEIGHT,
                METAL_RGBA,
                label,
            ))
            self._wall_box(
                wi,
                s_door + side * (ELEVATOR_WIDTH_M + fw) / 2.0,
                0.06,
                fw,
                0.0,
                ELEVATOR_HEIGHT + fw,
                STEEL_DARK_RGBA,
                label,
            )
        seam = self._wall_box(wi, s_door, 0.025, 0.04, 0.0, ELEVATOR_HEIGHT, STEEL_DARK_RGBA, label)
        leaves.append(seam)  # where the leaves meet: it slides with them
        self._wall_box(
            wi,
            s_door,
            0.06,
            ELEVATOR_WIDTH_M,
            ELEVATOR_HEIGHT,
            ELEVATOR_HEIGHT + fw,
            STEEL_DARK_RGBA,
            label,
        )
        panel = s_door - ELEVATOR_WIDTH_M / 2.0 - fw - ELEVATOR_PANEL_M / 2.0
        self._wall_box(wi, panel, 0.02, 0.12, 0.95, 1.25, STEEL_DARK_RGBA, label)
        self._wall_box(wi, panel, 0.015, 0.05, 1.05, 1.10, (0.95, 0.75, 0.2, 1.0), label, out=0.02)
        return self._item(
            lm.id,
            lm.kind,
            label,
            wi,
            s,
            total,
            (0.0, ELEVATOR_HEIGHT + fw),
            lm.sign_text,
        )

    def _build_cabins(self) -> None:
        """A cabin behind each of ``lift_lobbies`` (``sim/scene/lifts.py``), where the walls
        left its doorway: the lift's doors must hang where the wall nearest the landmark
        has them (``_build_walls``), not moved along it for want of room."""
        for lid in sorted(self.lift_lobbies):
            wi, s = self._where[landmark_label(lid)]
            near, s_near = self._placer.nearest(self.building.landmark(lid).pos)
            # grid: the annotated wall of the real one, in its measure
            on, s_on = self._mounts.annotated(wi, s) if self._mounts else (wi, s)
            if (on, round(s_on, 3)) != (near, round(s_near, 3)):
                raise SimError(
                    f"{self.building.name}: lift {lid} hangs {abs(s_on - s_near):.2f} m from its "
                    "point (no room on the wall there), so its cabin has no doorway; move it"
                )
            w = self.walls[wi]
            centre = w.point(doorway_s(s))
            self.cabins[lid] = build_cabin(
                self, lid, _xy(centre), w.normal, self._elevator_leaves[lid]
            )

    def _build_stairs(self, lm: Landmark, label: str) -> WallItem:
        wi, s = self._snap(landmark_item(lm.id), lm.pos, STAIRS.span_m / 2.0)
        step = STAIRS_LENGTH_M / STAIRS_STEPS
        for k in range(STAIRS_STEPS):
            sk = s - STAIRS_LENGTH_M / 2.0 + (k + 0.5) * step
            self._wall_box(
                wi, sk, STAIRS_DEPTH_M, step, 0.0, (k + 1) * STAIRS_RISE, STEP_RGBA[k % 2], label
            )
        top = STAIRS_STEPS * STAIRS_RISE
        return self._item(lm.id, lm.kind, label, wi, s, STAIRS_LENGTH_M, (0.0, top), lm.sign_text)

    def _build_desk(self, lm: Landmark, label: str) -> WallItem:
        wi, s = self._snap(landmark_item(lm.id), lm.pos, DESK.span_m / 2.0)
        top = DESK_HEIGHT - 0.04  # the desk, under its counter top
        self._wall_box(wi, s, DESK_DEPTH_M, DESK_LENGTH_M, 0.0, top, DESK_RGBA, label)
        self._wall_box(
            wi,
            s,
            DESK.depth_m,
            DESK.span_m,
            DESK_HEIGHT - 0.04,
            DESK_HEIGHT,
            COUNTER_RGBA,
            label,
        )
        return self._item(
            lm.id,
            lm.kind,
            label,
            wi,
            s,
            DESK.span_m,
            (0.0, DESK_HEIGHT),
            lm.sign_text,
        )
