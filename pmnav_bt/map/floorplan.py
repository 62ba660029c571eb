"""Floor plans: a building's optional plan image or ROS map, and a rasterised map of a building.

A floor plan is an image with a resolution (metres per pixel) and an origin, the
map pose ``(x, y, yaw)`` of the image's bottom-left corner, as ROS map_server
defines it: image column ``i`` and map cell row ``j = height - 1 - row`` cover
``origin + R(yaw) @ ([i, i + 1] * res, [j, j + 1] * res)``. World y points up, image
rows down. Pixel coordinates here are OpenCV's: pixel ``(col, row)`` has its
centre at those integers.

``rasterize_building`` draws a building as a map_server occupancy image (free
corridors, walls with door gaps, unknown elsewhere) and ``save_ros_map`` writes it
as PGM + YAML, so a building can be tried with a real map_server map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.loading import (
    MAX_IMAGE_PIXELS,
    InputFileError,
    atomic_write_text,
    image_size,
    is_regular_file,
    load_yaml,
)
from pmnav_bt.map.building import Building

# map_saver's grey levels and thresholds (trinary mode).
FREE, UNKNOWN, OCCUPIED = 254, 205, 0
DEFAULT_OCCUPIED_THRESH = 0.65
DEFAULT_FREE_THRESH = 0.196
MODES = ("trinary", "scale", "raw")

# Rasterised building: wall thickness, door width, how far a door gap reaches into the room.
WALL_M = 0.15
DOOR_WIDTH_M = 1.0
DOOR_INTO_ROOM_M = 0.5


class FloorPlanError(PmNavError):
    """A floor plan file (image or ROS map YAML) could not be read or is invalid."""

    def __init__(self, path: str | Path, field: str, message: str):
        self.path = str(path)
        self.field = field
        self.message = message
        super().__init__(f"{self.path}: {field}: {message}" if field else f"{self.path}: {message}")


@dataclass(frozen=True, eq=False)
class FloorPlanImage:
    """A floor plan image placed in the map frame, with map_server's reading of its pixels."""

    image: np.ndarray  # uint8, grey (H, W) or BGR (H, W, 3), rows as in the file
    resolution: float  # metres per pixel
    origin: tuple[float, float, float]  # map pose (x, y, yaw) of the bottom-left corner
    negate: bool = False
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH
    free_thresh: float = DEFAULT_FREE_THRESH
    mode: str = "trinary"
    source: str = "<memory>"

    @property
    def height(self) -> int:
        return int(self.image.shape[0])

    @property
    def width(self) -> int:
        return int(self.image.shape[1])

    def affine(self) -> np.ndarray:
        """The 2x3 matrix taking map (x, y) to pixel (col, row)."""
        ox, oy, yaw = self.origin
        c, s = math.cos(yaw), math.sin(yaw)
        r = 1.0 / self.resolution
        # local = R(-yaw) (w - o); col = local_x / res - 0.5; row = height - local_y / res - 0.5
        lin = np.array([[c * r, s * r], [s * r, -c * r]])
        off = np.array([-0.5, self.height - 0.5]) - lin @ np.array([ox, oy])
        return np.hstack([lin, off[:, None]])

    def world_to_pixel(self, xy) -> np.ndarray:
        """Map points (N, 2) to continuous pixel coordinates (col, row)."""
        m = self.affine()
        return _as_points(xy) @ m[:, :2].T + m[:, 2]

    def pixel_to_world(self, cr) -> np.ndarray:
        """Pixel coordinates (N, 2) (col, row) to map points; integers give pixel centres."""
        m = self.affine()
        return (_as_points(cr) - m[:, 2]) @ np.linalg.inv(m[:, :2]).T

    def world_to_cell(self, xy) -> np.ndarray:
        """The pixel (col, row) that contains each map point, as map_server/costmap index it."""
        ox, oy, yaw = self.origin
        c, s = math.cos(yaw), math.sin(yaw)
        d = _as_points(xy) - np.array([ox, oy])
        i = np.floor((c * d[:, 0] + s * d[:, 1]) / self.resolution)
        j = np.floor((-s * d[:, 0] + c * d[:, 1]) / self.resolution)
        return np.stack([i, self.height - 1 - j], axis=1).astype(int)

    def mask_at(self, mask: np.ndarray, xy) -> np.ndarray:
        """``mask`` (a boolean image of this plan's size, such as its free cells) at each
        map point (N,); False for points off the image."""
        cell = self.world_to_cell(xy)
        ok = (cell >= 0).all(axis=1) & (cell[:, 0] < self.width) & (cell[:, 1] < self.height)
        out = np.zeros(len(cell), bool)
        out[ok] = mask[cell[ok, 1], cell[ok, 0]]
        return out

    def corners_world(self) -> np.ndarray:
        """The image's four outer corners in the map frame (4, 2)."""
        w, h = self.width, self.height
        return self.pixel_to_world(
            [[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]]
        )

    def bgr(self) -> np.ndarray:
        """The image as 3-channel BGR (for drawing)."""
        img = self.image
        if img.ndim == 2:
            return cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
        return np.ascontiguousarray(img[:, :, :3])

    def grey(self) -> np.ndarray:
        """Mean of the colour channels (alpha left out), as map_server averages them."""
        img = self.image
        if img.ndim == 2:
            return img.astype(float)
        return img[:, :, :3].astype(float).mean(axis=2)

    def occupancy(self) -> np.ndarray:
        """map_server's occupancy per pixel (int8, rows as in the image).

        0 free, 100 occupied, -1 unknown; ``scale`` mode gives 1..99 in between and
        ``raw`` takes grey values 0..100 as they are.
        """
        shade = self.grey() / 255.0
        if self.mode == "raw":
            raw = np.rint(shade * 255.0)
            return np.where(raw <= 100, raw, -1).astype(np.int8)
        occ = shade if self.negate else 1.0 - shade
        out = np.full(occ.shape, -1, dtype=np.int8)
        if self.mode == "scale":
            span = self.occupied_thresh - self.free_thresh
            mid = np.rint((occ - self.free_thresh) / span * 100.0)
            out = np.clip(mid, 0, 100).astype(np.int8)
            if self.image.ndim == 3 and self.image.shape[2] == 4:
                out[self.image[:, :, 3] < 255] = -1
        out[occ > self.occupied_thresh] = 100
        out[occ < self.free_thresh] = 0
        return out


def _as_points(xy) -> np.ndarray:
    return np.asarray(xy, dtype=float).reshape(-1, 2)


# -- loading ---------------------------------------------------------------------------


def read_image(path: str | Path, field: str = "image") -> np.ndarray:
    """Read an 8-bit image file (PGM, PNG, JPG) as grey or BGR(A), or raise FloorPlanError."""
    path = Path(path)
    if not is_regular_file(path):
        raise FloorPlanError(path, field, "image file not found; check the path")
    try:
        image_size(path, field)  # from the header: no decoding of a 30000 x 30000 image
    except InputFileError as err:
        raise FloorPlanError(path, field, err.message) from None
    img = _imread_quiet(path)
    if img is None:
        raise FloorPlanError(path, field, "cannot decode the image; use a PGM, PNG or JPG file")
    if img.dtype != np.uint8:
        raise FloorPlanError(path, field, f"image is {img.dtype}; save it as 8-bit grey or colour")
    if img.ndim == 3 and img.shape[2] == 1:
        img = img[:, :, 0]
    return img


def _imread_quiet(path: Path) -> np.ndarray | None:
    """cv2.imread without OpenCV's own error lines on stderr (our message says it once)."""
    log = getattr(getattr(cv2, "utils", None), "logging", None)
    old = log.getLogLevel() if log is not None else None
    if log is not None:
        log.setLogLevel(log.LOG_LEVEL_SILENT)
    try:
        return cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except cv2.error:
        return None
    finally:
        if log is not None:
            log.setLogLevel(old)


def load_image_plan(
    path: str | Path, metres_per_pixel: float, origin: tuple[float, float] = (0.0, 0.0)
) -> FloorPlanImage:
    """A plain plan image whose bottom-left corner lies at ``origin`` (map frame)."""
    if not _is_number(metres_per_pixel) or metres_per_pixel <= 0:
        raise FloorPlanError(
            path, "metres_per_pixel", f"must be a positive number (got {metres_per_pixel!r})"
        )
    img = read_image(path, "floor_plan.image")
    ox, oy = (float(v) for v in origin)
    return FloorPlanImage(img, float(metres_per_pixel), (ox, oy, 0.0), source=str(path))


def load_ros_map(yaml_path: str | Path) -> FloorPlanImage:
    """A ROS map_server map: the YAML (image, resolution, origin, ...) and its image."""
    yaml_path = Path(yaml_path)
    data = _read_yaml(yaml_path)
    for key in ("image", "resolution", "origin"):
        if key not in data:
            raise FloorPlanError(
                yaml_path,
                key,
                "required key is missing; a map_server YAML needs image, resolution and origin",
            )
    if not isinstance(data["image"], str) or not data["image"]:
        raise FloorPlanError(yaml_path, "image", f"must be a file name (got {data['image']!r})")
    res = data["resolution"]
    if not _is_number(res) or not 0.001 <= res <= 10.0:
        raise FloorPlanError(
            yaml_path, "resolution", f"must be 0.001 to 10 metres per pixel (got {res!r})"
        )
    origin = data["origin"]
    if not (
        isinstance(origin, list)
        and len(origin) == 3
        and all(map(_is_number, origin))
        and all(abs(v) <= 100_000 for v in origin)
    ):
        raise FloorPlanError(
            yaml_path, "origin", f"must be [x, y, yaw] in metres and radians (got {origin!r})"
        )
    negate = data.get("negate", 0)
    if negate not in (0, 1):
        raise FloorPlanError(yaml_path, "negate", f"must be 0 or 1 (got {negate!r})")
    occ_t = data.get("occupied_thresh", DEFAULT_OCCUPIED_THRESH)
    free_t = data.get("free_thresh", DEFAULT_FREE_THRESH)
    for key, v in (("occupied_thresh", occ_t), ("free_thresh", free_t)):
        if not _is_number(v) or not 0.0 <= v <= 1.0:
            raise FloorPlanError(yaml_path, key, f"must be a number from 0 to 1 (got {v!r})")
    if free_t >= occ_t:
        raise FloorPlanError(
            yaml_path, "free_thresh", f"must be below occupied_thresh ({free_t} >= {occ_t})"
        )
    mode = data.get("mode", "trinary")
    if mode not in MODES:
        raise FloorPlanError(yaml_path, "mode", f"must be one of {', '.join(MODES)} (got {mode!r})")
    image_path = Path(data["image"])
    if not image_path.is_absolute():
        image_path = yaml_path.parent / image_path
    if not is_regular_file(image_path):
        raise FloorPlanError(
            yaml_path,
            "image",
            f"image file not found: {image_path} (paths are relative to the YAML)",
        )
    return FloorPlanImage(
        read_image(image_path, "image"),
        float(res),
        (float(origin[0]), float(origin[1]), float(origin[2])),
        negate=bool(negate),
        occupied_thresh=float(occ_t),
        free_thresh=float(free_t),
        mode=mode,
        source=str(yaml_path),
    )


def load_floor_plan(building: Building, base_dir: str | Path = ".") -> FloorPlanImage | None:
    """The building's floor plan (paths relative to ``base_dir``), or None if it has none."""
    spec = building.floor_plan
    if spec is None:
        return None
    base = Path(base_dir)
    if spec.ros_map is not None:
        return load_ros_map(base / spec.ros_map)
    return load_image_plan(base / spec.image, spec.metres_per_pixel, spec.origin)


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        data = load_yaml(path, "ros_map")
    except InputFileError as err:
        raise FloorPlanError(path, err.field, err.message) from None
    if not isinstance(data, dict):
        raise FloorPlanError(
            path, "", "expected a mapping with image, resolution and origin (a map_server YAML)"
        )
    return data


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


# -- saving ----------------------------------------------------------------------------


def save_ros_map(plan: FloorPlanImage, yaml_path: str | Path, image_suffix: str = ".pgm") -> Path:
    """Write ``plan`` as a map_server map: ``<stem>.pgm`` (or .png) beside the YAML.

    Returns the YAML path.
    """
    yaml_path = Path(yaml_path)
    pgm = yaml_path.with_suffix(image_suffix)
    grey = plan.image if plan.image.ndim == 2 else np.rint(plan.grey()).astype(np.uint8)
    if not cv2.imwrite(str(pgm), grey):
        raise FloorPlanError(pgm, "", "cannot write the map image; check the folder exists")
    meta = {
        "image": pgm.name,
        "mode": plan.mode,
        "resolution": float(plan.resolution),
        "origin": [float(v) for v in plan.origin],
        "negate": int(plan.negate),
        "occupied_thresh": float(plan.occupied_thresh),
        "free_thresh": float(plan.free_thresh),
    }
    atomic_write_text(yaml_path, yaml.safe_dump(meta, sort_keys=False))
    return yaml_path


# -- building geometry and rasterising -------------------------------------------------


@dataclass(frozen=True)
class DoorFrame:
    """A door on its corridor: the centre-line foot, unit vectors along and out, wall offset."""

    room: str
    door: tuple[float, float]
    foot: tuple[float, float]  # nearest point on the corridor centre line
    along: tuple[float, float]  # unit, along the corridor
    out: tuple[float, float]  # unit, from the centre line towards the room
    wall: float  # distance of the wall from the centre line (half the corridor width)


def corridor_quads(building: Building, grow: float = 0.0) -> list[np.ndarray]:
    """Each corridor edge as a rectangle (4, 2) of its width, ends extended by half the width.

    ``grow`` widens every side (for walls). Extending the ends fills turns and forks.
    """
    wps = {w.id: np.asarray(w.pos, dtype=float) for w in building.waypoints}
    quads = []
    for e in building.edges:
        a, b = wps[e.a], wps[e.b]
        u = (b - a) / np.linalg.norm(b - a)
        n = np.array([-u[1], u[0]])
        h = building.edge_width(e) / 2.0 + grow
        a2, b2 = a - u * h, b + u * h
        quads.append(np.array([a2 + n * h, b2 + n * h, b2 - n * h, a2 - n * h]))
    return quads


def door_frames(building: Building) -> list[DoorFrame]:
    """Every room's door on its nearest corridor."""
    if not building.rooms:
        return []
    wps = {w.id: np.asarray(w.pos, dtype=float) for w in building.waypoints}
    seg_a = np.array([wps[e.a] for e in building.edges])
    seg_b = np.array([wps[e.b] for e in building.edges])
    doors = np.array([r.door for r in building.rooms], dtype=float)
    idx, t, _ = project_points_to_segments(doors, seg_a, seg_b)
    frames = []
    for room, door, j, tj in zip(building.rooms, doors, idx, t, strict=True):
        a, b = seg_a[j], seg_b[j]
        u = (b - a) / np.linalg.norm(b - a)
        foot = a + tj * (b - a)
        n = np.array([-u[1], u[0]])
        if float(np.dot(door - foot, n)) < 0.0:
            n = -n
        wall = building.edge_width(building.edges[j]) / 2.0
        frames.append(DoorFrame(room.id, _xy(door), _xy(foot), _xy(u), _xy(n), wall))
    return frames


def door_gap(frame: DoorFrame, width: float = DOOR_WIDTH_M, depth: float = 0.0) -> np.ndarray:
    """The door opening (4, 2): from the centre line through the wall to ``depth`` past it."""
    foot, u, n = (np.asarray(v) for v in (frame.foot, frame.along, frame.out))
    reach = max(frame.wall, float(np.dot(np.asarray(frame.door) - foot, n))) + depth
    h = width / 2.0
    return np.array(
        [foot - u * h, foot + u * h, foot + u * h + n * reach, foot - u * h + n * reach]
    )


def building_bounds(building: Building, margin: float = 0.0) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the corridors, doors and landmarks, plus ``margin``."""
    pts = corridor_quads(building, WALL_M)
    pts += [door_gap(f, depth=WALL_M + DOOR_INTO_ROOM_M) for f in door_frames(building)]
    pts += [np.array([lm.pos for lm in building.landmarks]).reshape(-1, 2)]
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0) - margin, allp.max(axis=0) + margin
    return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def rasterize_building(
    building: Building, resolution: float = 0.05, margin: float = 2.0
) -> FloorPlanImage:
    """A map_server occupancy image of the building: free corridors and door gaps, walls, unknown.

    Grey levels are map_saver's (254 free, 0 occupied, 205 unknown). Each door is a
    gap of DOOR_WIDTH_M in the wall, free DOOR_INTO_ROOM_M into the room.
    """
    if not _is_number(resolution) or resolution <= 0:
        raise FloorPlanError("<rasterize>", "resolution", f"must be positive (got {resolution!r})")
    xmin, ymin, xmax, ymax = building_bounds(building, margin)
    w = math.ceil((xmax - xmin) / resolution)
    h = math.ceil((ymax - ymin) / resolution)
    if w * h > MAX_IMAGE_PIXELS:
        raise FloorPlanError(
            f"<rasterized {building.name}>",
            "resolution",
            f"{w}x{h} pixels at {resolution} m per pixel; use a coarser resolution",
        )
    plan = FloorPlanImage(
        np.full((h, w), UNKNOWN, dtype=np.uint8),
        float(resolution),
        (xmin, ymin, 0.0),
        source=f"<rasterized {building.name}>",
    )
    fill_world_polygons(plan, corridor_quads(building, WALL_M), OCCUPIED)
    fill_world_polygons(plan, corridor_quads(building), FREE)
    gaps = [door_gap(f, depth=WALL_M + DOOR_INTO_ROOM_M) for f in door_frames(building)]
    fill_world_polygons(plan, gaps, FREE)
    return plan


def fill_world_polygons(plan: FloorPlanImage, polys: list[np.ndarray], value: int) -> None:
    """Set, in place, every pixel whose centre lies inside one of the convex map-frame polygons."""
    last = np.array([plan.width - 1, plan.height - 1])
    for poly in polys:
        pix = plan.world_to_pixel(poly)
        c0, r0 = np.maximum(np.floor(pix.min(axis=0)), 0).astype(int)
        c1, r1 = np.minimum(np.ceil(pix.max(axis=0)), last).astype(int)
        if c1 < c0 or r1 < r0:
            continue
        cols, rows = np.meshgrid(np.arange(c0, c1 + 1), np.arange(r0, r1 + 1))
        inside = _inside_convex(pix, cols, rows)
        plan.image[r0 : r1 + 1, c0 : c1 + 1][inside] = value


def _inside_convex(poly: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Points (x, y) inside or on a convex polygon (K, 2) of either orientation."""
    pos = np.ones(x.shape, dtype=bool)
    neg = np.ones(x.shape, dtype=bool)
    for p, q in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        cross = (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])
        pos &= cross >= 0
        neg &= cross <= 0
    return pos | neg


def _xy(v) -> tuple[float, float]:
    return float(v[0]), float(v[1])
