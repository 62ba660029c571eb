"""Read one level of an Open-RMF traffic-editor building (``*.building.yaml``), in metres.

A traffic-editor file draws each level over a floor-plan image: every point is a
``vertex`` ``[x, y, z, name, params]`` in the drawing's **pixels** (x to the right, y
**down**, as image rows run), and ``walls``, ``doors``, ``lanes`` and ``measurements``
join two vertices by their index. A measurement gives the real distance between its two
vertices, so the scale is the mean over a level's measurements of metres per pixel.
Parameters are ``name: [type, value]`` pairs (type 1 text, 2 integer, 3 number, 4 bool).
Lifts are building-wide, placed in the pixels of their ``reference_floor_name`` level.

The map frame here is RMF's own world frame (REP-103, y up): a pixel ``(px, py)`` lies
at ``(px * scale, -py * scale)`` metres. The minus sign is the flip from image rows
(down) to the map's y (up); the building's coordinates are therefore the ones RMF's fleet
adapters use, mostly negative in y.

Everything is checked as it is read: a file that is not an RMF building, a level that is
not there, no measurements, an index to a vertex that does not exist, a number that is not
finite or puts a point beyond ``MAX_COORD_M`` raises ``RmfFileError`` (one line naming the
file and the field).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import Point, Polygon

from pmnav_bt.loading import InputFileError, load_yaml

MAX_COORD_M = 1000.0  # the building format's coordinate limit
MAX_ITEMS = 100_000  # vertices, walls, doors, lanes per level


class RmfFileError(InputFileError):
    """An Open-RMF building file that cannot be imported (one line: file, field, problem)."""


@dataclass(frozen=True)
class Link:
    """A wall, door or lane: two vertex indices and the link's parameters."""

    a: int
    b: int
    params: dict[str, Any]

    @property
    def name(self) -> str:
        return str(param(self.params, "name") or "")


@dataclass(frozen=True)
class LiftDoor:
    """A lift's door on this level: the lift, the door and the door's centre (metres), and
    the ``cabin``'s floor (four corners, metres): the shaft the door opens into, which is
    no corridor (RMF's lanes run on into it, to the cabin's middle)."""

    lift: str
    door: str
    pos: tuple[float, float]
    cabin: tuple[tuple[float, float], ...] = ()

    @property
    def along(self) -> np.ndarray:
        """The direction of the wall the door is in (the cabin's width)."""
        return np.subtract(self.cabin[1], self.cabin[0])


@dataclass
class RmfLevel:
    """One level in metres (RMF's world frame), with what joins its vertices."""

    source: str
    name: str
    scale: float  # metres per drawing pixel
    xy: np.ndarray  # (N, 2) vertex positions, metres
    names: list[str]  # vertex names ("" when unnamed)
    vparams: list[dict[str, Any]]  # vertex parameters (is_charger, spawn_robot_name, ...)
    walls: list[Link]
    doors: list[Link]
    lanes: list[Link]
    floors: list[list[int]]  # floor polygons, as vertex indices
    drawing: str | None  # the level's drawing, relative to the RMF file
    lift_doors: list[LiftDoor] = field(default_factory=list)


def param(params: dict[str, Any], key: str) -> Any:
    """The value of an RMF ``[type, value]`` parameter, or None when absent or malformed."""
    v = params.get(key) if isinstance(params, dict) else None
    return v[1] if isinstance(v, list) and len(v) == 2 else None


def level_elevations(path: str | Path) -> dict[str, float]:
    """Each level's name and elevation (metres; 0 where the file gives none), in file order."""
    src = str(path)
    levels = _levels(load_yaml(path, "building"), src)
    out = {}
    for name, raw in levels.items():
        z = raw.get("elevation", 0.0) if isinstance(raw, dict) else 0.0
        out[str(name)] = _number(z, src, f"levels.{name}.elevation")
    return out


def read_level(path: str | Path, level: str | None = None) -> RmfLevel:
    """Level ``level`` (default: the first) of the RMF building at ``path``, in metres."""
    src = str(path)
    data = load_yaml(path, "building")
    levels = _levels(data, src)
    if level is None:
        level = next(iter(levels))
    elif level not in levels:
        raise RmfFileError(
            src, f"no level {level!r}; the file has {', '.join(map(str, levels))}", "--level"
        )
    raw = levels[level]
    where = f"levels.{level}"
    px, names, vparams = _vertices(raw, src, where)
    links = {
        key: _links(raw, key, len(px), src, where) for key in ("walls", "doors", "lanes")
    }
    scale = _scale(raw, px, src, where)
    xy = np.stack([px[:, 0] * scale, -px[:, 1] * scale], axis=1) if len(px) else px
    _check_extent(xy, src, f"{where}.vertices")
    floors = []
    for i, fl in enumerate(_list(raw, "floors", src, where)):
        ids = fl.get("vertices") if isinstance(fl, dict) else None
        if not isinstance(ids, list) or not all(_index_ok(k, len(px)) for k in ids):
            raise RmfFileError(src, "vertices must be indices of this level's vertices",
                               f"{where}.floors[{i}]")
        floors.append(list(ids))
    drawing = raw.get("drawing")
    fname = drawing.get("filename") if isinstance(drawing, dict) else None
    lvl = RmfLevel(
        src, str(level), scale, xy, names, vparams, links["walls"], links["doors"],
        links["lanes"], floors, fname if isinstance(fname, str) and fname else None,
    )
    lvl.lift_doors = _lift_doors(data.get("lifts"), levels, lvl, src)
    lvl.lanes = _lanes_off_cabins(lvl)
    return lvl


def _lanes_off_cabins(lvl: RmfLevel) -> list:
    """The level's lanes less those with an end in a lift's cabin: RMF runs a lane on
    through a lift's door to the cabin's middle for the ride, which is no corridor (kept,
    it would make one into the lift's shaft, and the door would be at its dead end)."""
    cabins = [Polygon(d.cabin) for d in lvl.lift_doors if d.cabin]
    inside = {k for k, q in enumerate(lvl.xy) if any(c.contains(Point(q)) for c in cabins)}
    return [ln for ln in lvl.lanes if ln.a not in inside and ln.b not in inside]


# -- checks ---------------------------------------------------------------------------


def _vertices(raw: Any, src: str, where: str) -> tuple[np.ndarray, list[str], list[dict]]:
    """Vertex pixels (N, 2), names and parameters of a level."""
    if not isinstance(raw, dict):
        raise RmfFileError(src, "must be a mapping (vertices, walls, ...)", where)
    verts = _list(raw, "vertices", src, where, required=True)
    px = np.zeros((len(verts), 2))
    names, vparams = [], []
    for i, v in enumerate(verts):
        f = f"{where}.vertices[{i}]"
        if not isinstance(v, list) or len(v) < 2:
            raise RmfFileError(src, "a vertex is [x, y, z, name, params]", f)
        px[i] = (_number(v[0], src, f), _number(v[1], src, f))
        name = v[3] if len(v) > 3 else ""
        names.append(name if isinstance(name, str) else str(name))
        vparams.append(v[4] if len(v) > 4 and isinstance(v[4], dict) else {})
    return px, names, vparams


def _levels(data: Any, src: str) -> dict:
    if not isinstance(data, dict):
        raise RmfFileError(src, "not an Open-RMF building: expected a mapping with 'levels'")
    system = data.get("coordinate_system", "reference_image")
    if system != "reference_image":
        raise RmfFileError(
            src, f"{system!r} is not supported; only 'reference_image' (pixels and measurements)",
            "coordinate_system",
        )
    levels = data.get("levels")
    if not isinstance(levels, dict) or not levels:
        raise RmfFileError(src, "no levels: an Open-RMF building has a 'levels' mapping", "levels")
    return levels


def _number(v: Any, src: str, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise RmfFileError(src, f"must be a finite number (got {v!r:.40})", where)
    if abs(v) > 1e9:
        raise RmfFileError(src, f"number out of range (got {v!r:.40})", where)
    return float(v)


def _list(raw: dict, key: str, src: str, where: str, required: bool = False) -> list:
    v = raw.get(key)
    if v is None and not required:
        return []
    if not isinstance(v, list) or (required and not v):
        raise RmfFileError(src, "must be a non-empty list" if required else "must be a list",
                           f"{where}.{key}")
    if len(v) > MAX_ITEMS:
        raise RmfFileError(src, f"{len(v)} items; at most {MAX_ITEMS}", f"{where}.{key}")
    return v


def _index_ok(k: Any, n: int) -> bool:
    return isinstance(k, int) and not isinstance(k, bool) and 0 <= k < n


def _links(raw: dict, key: str, n: int, src: str, where: str) -> list[Link]:
    out = []
    for i, item in enumerate(_list(raw, key, src, where)):
        f = f"{where}.{key}[{i}]"
        if not isinstance(item, list) or len(item) < 2:
            raise RmfFileError(src, "expected [vertex, vertex, params]", f)
        for k in item[:2]:
            if not _index_ok(k, n):
                raise RmfFileError(
                    src, f"vertex {k!r:.20} does not exist (the level has {n} vertices)", f
                )
        params = item[2] if len(item) > 2 and isinstance(item[2], dict) else {}
        out.append(Link(item[0], item[1], params))
    return out


def _scale(raw: dict, px: np.ndarray, src: str, where: str) -> float:
    """Metres per pixel: the mean over the level's measurements."""
    meas = _links(raw, "measurements", len(px), src, where)
    if not meas:
        raise RmfFileError(
            src, "none: the scale (metres per pixel) comes from the measurements; "
            "add one in traffic-editor", f"{where}.measurements",
        )
    ratios = []
    for i, m in enumerate(meas):
        f = f"{where}.measurements[{i}]"
        dist = _number(param(m.params, "distance"), src, f"{f}.distance")
        pixels = float(np.linalg.norm(px[m.a] - px[m.b]))
        if dist <= 0 or pixels <= 0:
            raise RmfFileError(src, "needs two distinct vertices and a distance above 0", f)
        ratios.append(dist / pixels)
    return float(np.mean(ratios))


def _check_extent(xy: np.ndarray, src: str, where: str) -> None:
    if len(xy) and float(np.abs(xy).max()) > MAX_COORD_M:
        i = int(np.abs(xy).max(axis=1).argmax())
        raise RmfFileError(
            src, f"vertex {i} lies {float(np.abs(xy[i]).max()):.3g} m out; a building's "
            f"coordinates must be within {MAX_COORD_M:g} m (check the measurements)", where,
        )


def _lift_doors(lifts: Any, levels: dict, lvl: RmfLevel, src: str) -> list[LiftDoor]:
    """The doors of every lift that serves this level, placed in metres.

    A lift's ``x``/``y`` are pixels of its reference level (scaled by that level's
    measurements), ``yaw`` its heading in the map frame, and each door's ``x``/``y`` metres
    in the cabin's frame.
    """
    if lifts is None:
        return []
    if not isinstance(lifts, dict):
        raise RmfFileError(src, "must be a mapping of lift names", "lifts")
    out = []
    for name, lift in lifts.items():
        f = f"lifts.{name}"
        if not isinstance(lift, dict):
            raise RmfFileError(src, "must be a mapping", f)
        served = lift.get("level_doors") or {}
        if not isinstance(served, dict) or lvl.name not in served:
            continue
        ref = lift.get("reference_floor_name", lvl.name)
        scale = lvl.scale
        if ref != lvl.name and ref in levels:
            where = f"levels.{ref}"
            scale = _scale(levels[ref], _vertices(levels[ref], src, where)[0], src, where)
        cx, cy, yaw = (_number(lift.get(k), src, f"{f}.{k}") for k in ("x", "y", "yaw"))
        centre = np.array([cx * scale, -cy * scale])
        rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
        cabin: tuple[tuple[float, float], ...] = ()
        if "width" in lift and "depth" in lift:  # the cabin's size, metres
            half = np.array([_number(lift[k], src, f"{f}.{k}") for k in ("width", "depth")]) / 2
            corners = (centre + rot @ (half * sx) for sx in ((-1, -1), (1, -1), (1, 1), (-1, 1)))
            cabin = tuple((float(q[0]), float(q[1])) for q in corners)
        doors = lift.get("doors") or {}
        names = served[lvl.name] if isinstance(served[lvl.name], list) else []
        for dname in names:
            d = doors.get(dname) if isinstance(doors, dict) else None
            if not isinstance(d, dict):
                raise RmfFileError(src, f"door {dname!r:.40} is not in the lift's doors", f)
            off = np.array([_number(d.get(k), src, f"{f}.doors.{dname}.{k}") for k in "xy"])
            pos = centre + rot @ off
            _check_extent(pos[None], src, f)
            out.append(LiftDoor(str(name), str(dname), (float(pos[0]), float(pos[1])), cabin))
    return out
