"""Plates seen but not read: where they hang, which way they face, how big their text is.

A reader finds a plate long before it can read it: the candidate finder
(``signs.SignReader.candidates``) sees a small, dense patch of text from 4-5 m where the
recogniser needs the capitals a dozen pixels high. Such a plate is not "absent": the
robot can go where it is read (``behaviours/active_read.py``). A plate is *unread* when
its text was not read at all, or was read and fits a room of the building as well as
another or no better than a plate the building does not hold (``ambiguous``: below the
matcher's confidence), or was read unsure (``SignMatcher.unsure``: a character read at a
confidence the OCR is often wrong at, or a code spelled as none of the building's: "79"
where the rooms are "209"s is a plate misread, not a plate the building lacks). A read
that surely names nothing of the map (a directional sign, a notice) is not unread: it
was read.

What the tree needs of an unread plate comes from depth (``depth.plate_pose``): its
centre and which way its text faces in the odometry frame (the wall's normal; along the
wall, towards where it was seen, for text read more aslant than a flat plate is read:
a flag sign, ``text_facing``), the height of its centre, and its
text-line height in metres (the candidate's line height in pixels at the plate's depth),
by which the reading model says from how far a plate of that size is read
(``read_range.plate_read_range``). Candidates that cannot be plates (off the wall's
height, too wide, text too tall) are left out.

A grounder that reads plates remembers the unread ones (``UnreadPlates``, odometry frame,
one entry per place, the newest sighting kept, dropped once the plate is read) and tells
the tree through ``SeesUnreadPlates``. The oracle (``sim_gt``) reads every sign it sees:
it has none.

It also remembers, per room or landmark, the last plate it read as naming it
(``plate_named``), placed the same way: a search that does not see a plate already read
(it hangs above the view from where the search stands, a person stands before it) has
not found it absent, and the tree reads it again from where it reads.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from pmnav_bt.perception.depth import PlatePose, back_project, plate_pose
from pmnav_bt.perception.door_scene import plate_wall
from pmnav_bt.perception.read_range import ANGLE_RECALL
from pmnav_bt.perception.sign_match import Evidence
from pmnav_bt.seams import Entity, Observation

SAME_PLATE_M = 0.4  # two sightings this near are one plate
PLATE_Z_M = (1.1, 2.7)  # a plate's centre above the floor: door plates to flag signs
BORDER_PX = 2  # a candidate this near the frame's border is cut off: not judged
MAX_PLATE_WIDTH_M = 1.2
# A text line of a room plate: 20-80 mm capitals, a line 1.3 times as high, and the finder
# measures it higher yet from afar (sign_ranges: 38 mm for 25 mm capitals). Below 20 mm
# it is no plate's text: a door's frame or lintel, a handle, a skirting's edge.
LINE_HEIGHT_M = (0.02, 0.2)
MAX_SEEN_M = 8.0  # farther than this, depth places a plate too poorly to drive to
KEEP_S = 120.0  # an unread plate is remembered this long (clock s)
FLAT_READ_DEG = ANGLE_RECALL[-2][0]  # (75) no flat plate is read farther off its normal


@dataclass(frozen=True)
class UnreadPlate:
    """A plate seen but not read, in the odometry frame: ``xy`` its centre on the wall,
    ``normal`` the wall's unit normal out towards where it was seen from, ``z`` its
    centre's height above the floor, ``top`` the height of its text's top (what a level
    camera must keep in view to read it), ``line_height`` its text-line height (m),
    ``width`` along the wall (m); ``stamp`` when and ``seen_from`` where it was seen;
    ``read`` what was read of it ("" nothing)."""

    xy: tuple[float, float]
    normal: tuple[float, float]
    z: float
    top: float
    line_height: float
    width: float
    stamp: float
    seen_from: tuple[float, float]
    read: str = ""


@runtime_checkable
class SeesUnreadPlates(Protocol):
    """A grounder that remembers the plates it saw but could not read (``UnreadPlate``,
    odometry frame), seen at or after clock time ``since``."""

    def unread_plates(self, since: float) -> list[UnreadPlate]: ...

    def plate_named(self, entity: Entity) -> UnreadPlate | None:
        """The plate last read as naming ``entity`` (``read`` its text; ``stamp`` when);
        None: none."""
        ...


def ambiguous(ev: Evidence) -> bool:
    """Whether a read that named nothing still fits a room or landmark as well as the
    plate the building does not hold: a read below the matcher's confidence (look
    nearer), not a plate that names nothing of the map."""
    return bool(ev.entities) and max(ev.entities.values()) >= ev.unknown


def hangs_like_a_plate(obs: Observation, plate: PlatePose) -> bool:
    """Whether depth puts ``plate`` where signs hang: its centre ``PLATE_Z_M`` above the
    floor, no wider than ``MAX_PLATE_WIDTH_M``."""
    height = float(plate.centre[2]) + obs.camera_height
    return PLATE_Z_M[0] <= height <= PLATE_Z_M[1] and plate.width <= MAX_PLATE_WIDTH_M


def text_facing(
    centre: tuple[float, float],
    normal: tuple[float, float],
    read: bool,
    across: tuple[float, float] | None = None,
) -> tuple[float, float]:
    """Which way a plate's text faces (unit, camera body frame), from its ``centre`` and
    depth's ``normal`` (towards the camera). A flag sign stands across its wall: where
    depth shows one (``across``: its wall's direction, ``door_scene.plate_wall``), its text
    faces along that wall, towards the camera. Depth's normal of a flag seen end-on is
    the wall's, or anything (its box holds more wall than plate); yet text that was
    ``read`` faced the camera within ``FLAT_READ_DEG`` of its normal (no flat plate is
    read beyond: ``read_range.ANGLE_RECALL``). So a plate read more aslant than that
    projects across its wall too: along the wall, square to depth's normal."""
    n = np.asarray(normal, float)
    to_camera = -np.asarray(centre, float)
    dist = float(np.linalg.norm(to_camera))
    if dist < 1e-6:
        return float(n[0]), float(n[1])
    to_camera /= dist
    if across is not None:
        along = np.asarray(across, float) / max(float(np.linalg.norm(across)), 1e-9)
    elif not read or _degrees_between(n, to_camera) <= FLAT_READ_DEG:
        return float(n[0]), float(n[1])
    else:
        along = np.array([n[1], -n[0]])
    along = along if float(along @ to_camera) >= 0.0 else -along
    return float(along[0]), float(along[1])


def _degrees_between(a: np.ndarray, b: np.ndarray) -> float:
    """The angle (deg) between unit vectors ``a`` and ``b``."""
    return math.degrees(math.acos(float(np.clip(a @ b, -1.0, 1.0))))


def unread_plate(
    obs: Observation,
    box: tuple[float, float, float, float],
    line_px: float,
    read: str = "",
    *,
    flags: bool = False,
    text_top_px: float | None = None,
) -> UnreadPlate | None:
    """The plate in ``box`` (frame pixels; ``line_px`` its text-line height in them) as
    depth places it, in the odometry frame; None without depth or where it cannot be a
    plate (see the module docstring). ``flags``: ask depth whether the plate stands across
    its wall (``door_scene.plate_wall``; tens of ms), to know which way its text faces.
    ``text_top_px``: the row of its text's top where text was read (else the box's top,
    which takes in the plate's border and frame)."""
    h, w = obs.rgb.shape[:2]
    if min(box[0], box[1], w - 1 - box[2], h - 1 - box[3]) < BORDER_PX:
        return None
    plate = plate_pose(obs, box)
    if plate is None:
        return None
    across = None
    if flags:
        wall = plate_wall(obs, back_project(obs), plate, box)
        across = (float(wall.left[0]), float(wall.left[1])) if wall.flag else None
    x, y, z = (float(v) for v in plate.centre)
    k = obs.intrinsics
    line = line_px * x / k.fy
    height = z + obs.camera_height
    top_row = box[1] if text_top_px is None else text_top_px
    top = obs.camera_height + (k.cy - top_row) * x / k.fy  # the text's top at its depth
    if not (
        hangs_like_a_plate(obs, plate)
        and LINE_HEIGHT_M[0] <= line <= LINE_HEIGHT_M[1]
        and math.hypot(x, y) <= MAX_SEEN_M
    ):
        return None
    p = obs.pose
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    nx, ny = text_facing(
        (x, y), (float(plate.normal[0]), float(plate.normal[1])), bool(read), across
    )
    return UnreadPlate(
        xy=(p.x + c * x - s * y, p.y + s * x + c * y),
        normal=(c * nx - s * ny, s * nx + c * ny),
        z=height,
        top=max(top, height),
        line_height=line,
        width=plate.width,
        stamp=obs.stamp,
        seen_from=(p.x, p.y),
        read=read,
    )


class UnreadPlates:
    """The unread plates a grounder saw (thread-safe: frames are read in the worker)."""

    def __init__(self) -> None:
        self._plates: list[UnreadPlate] = []
        self._named: dict[Entity, UnreadPlate] = {}
        self._lock = threading.Lock()

    def named(self, entity: Entity, plate: UnreadPlate) -> None:
        """``plate`` was read as naming ``entity``: it is unread no more, and is where
        ``entity``'s plate hangs."""
        with self._lock:
            self._plates = [p for p in self._plates if not _same(p, plate.xy)]
            self._named[entity] = plate

    def plate_named(self, entity: Entity) -> UnreadPlate | None:
        with self._lock:
            return self._named.get(entity)

    def seen(self, plate: UnreadPlate) -> None:
        """Remember ``plate``, in place of an earlier sighting of it."""
        with self._lock:
            self._plates = [p for p in self._forget(plate.stamp) if not _same(p, plate.xy)]
            self._plates.append(plate)

    def read_at(self, xy: tuple[float, float]) -> None:
        """The plate at ``xy`` (odometry frame) was read: it is unread no more."""
        with self._lock:
            self._plates = [p for p in self._plates if not _same(p, xy)]

    def since(self, t: float) -> list[UnreadPlate]:
        with self._lock:
            return [p for p in self._plates if p.stamp >= t]

    def _forget(self, now: float) -> list[UnreadPlate]:
        return [p for p in self._plates if now - p.stamp <= KEEP_S]


def _same(p: UnreadPlate, xy: tuple[float, float]) -> bool:
    return math.dist(p.xy, xy) <= SAME_PLATE_M
