"""Doors seen along the corridor's walls, far beyond where their signs can be read.

A sign is read from 3.5 m at most, but the door beside it shows from much farther: a
panel unlike the wall it stands in. Along each wall line fitted in depth
(``walls.wall_lines``), the wall pixels at door-handle height (``BAND_M``, below the
sign plates, above the skirting) are placed along the line; the wall's own colour is
the median (CIELAB) of the same wall above the doors (``REF_BAND_M``: where doors are
many, a door-height median is a door's colour), and runs of pixels far from it
(``MIN_CONTRAST``, lightness at half weight: a face of the wall shaded otherwise, such
as the end of a grid map's staggered wall box, is not a door), a door's width long,
are doors. Which door each is cannot be told
(that is the sign's job): the corridor belief weighs where doors are seen, and where
the map has doors that are not.

The same cue as ``doors.door_from_sign`` (a door looks unlike its wall), taken along
the whole wall. In the simulator's 320x240 views (``benchmarks/bench_door_sightings.py``,
660 views of eleven buildings) doors 4-13 m off are found 95 % of the time, 13-16 m off
81 %, and nothing is found where no door or landmark is; far along the wall one image
column spans 0.3 m of it, so bins no pixel falls in do not break a door's run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from pmnav_bt.perception.depth import back_project, normals
from pmnav_bt.pose.walls import wall_lines, wall_points
from pmnav_bt.seams import Observation

DOOR_RANGE_M = 14.0  # doors are looked for this far along the walls
BAND_M = (0.3, 1.1)  # height above the floor of the pixels looked at
REF_BAND_M = (2.25, 2.6)  # ... and of the wall's own colour: above door frames (2.2 m)
ON_LINE_M = 0.12  # a pixel this close to a wall line is on that wall (frames stand 4 cm out)
FACING = 0.9  # ... and faces the way the wall does (|cos| of the normals' angle): the
# ends of a grid map's staggered wall boxes face along the corridor, shaded darker
MIN_CONTRAST = 20.0  # CIELAB distance from the wall's colour of a door pixel, lightness
LIGHTNESS_WEIGHT = 0.5  # ... counted at half: a face shaded otherwise differs in lightness
BIN_M = 0.1  # pixels are binned this finely along the wall
BIN_DOOR_SHARE = 0.5  # a bin whose pixels are this much door colour is door
MIN_BIN_PX = 2  # ... with at least this many of them
GAP_M = 0.25  # a door's run ends at wall bins this long
DOOR_WIDTH_M = (0.4, 2.6)  # a run this long is a door (an elevator's pair of doors: 2 m)
MIN_WALL_PX = 200  # a wall line needs this many band pixels to be looked along ...
MIN_REF_PX = 40  # ... and this many above the doors for its colour to be known


@dataclass(frozen=True)
class DoorSeen:
    """A door on a wall: its centre (camera body frame, floor plane: x ahead, y left, m),
    its length along the wall (m) and the wall's direction (rad, body frame, mod pi)."""

    centre: tuple[float, float]
    width: float
    wall_angle: float


def find_doors(
    obs: Observation, wall: np.ndarray, max_range: float = DOOR_RANGE_M
) -> list[DoorSeen]:
    """The doors on the wall lines in view (``wall``: the frame's wall mask), nearest first."""
    if obs.depth is None or not wall.any():
        return []
    lines = wall_lines(wall_points(obs, wall), 2)
    if not lines:
        return []
    pts = back_project(obs)
    height = pts[..., 2] + obs.camera_height
    h = np.nan_to_num(height, nan=-1.0)
    near = np.nan_to_num(pts[..., 0], nan=1e9) <= max_range
    band = wall & near & (h > BAND_M[0]) & (h < BAND_M[1])
    above = wall & near & (h > REF_BAND_M[0]) & (h < REF_BAND_M[1])
    if not band.any() or not above.any():
        return []
    lab_image = cv2.cvtColor(obs.rgb, cv2.COLOR_RGB2LAB)
    xy, lab = pts[band][:, :2].astype(float), lab_image[band].astype(np.float32)
    facing = np.nan_to_num(normals(pts)[band][:, :2])
    xy_ref, lab_ref = pts[above][:, :2].astype(float), lab_image[above].astype(np.float32)
    found: list[DoorSeen] = []
    for line in lines:
        d = np.array([math.cos(line.angle), math.sin(line.angle)])
        n = np.array([-d[1], d[0]])
        on = (np.abs(xy @ n - line.offset) <= ON_LINE_M) & (np.abs(facing @ n) >= FACING)
        on_ref = np.abs(xy_ref @ n - line.offset) <= ON_LINE_M
        if on.sum() < MIN_WALL_PX or on_ref.sum() < MIN_REF_PX:
            continue
        colour = lab[on]
        ref = np.median(lab_ref[on_ref], axis=0)
        diff = (colour - ref) * np.array([LIGHTNESS_WEIGHT, 1.0, 1.0], np.float32)
        door = np.linalg.norm(diff, axis=1) > MIN_CONTRAST
        s = xy[on] @ d
        found += [
            DoorSeen(tuple(float(v) for v in mid * d + line.offset * n), width, line.angle)  # type: ignore[arg-type]
            for mid, width in _runs(s, door)
        ]
    return sorted(found, key=lambda f: math.hypot(*f.centre))


def _runs(s: np.ndarray, door: np.ndarray) -> list[tuple[float, float]]:
    """(middle, length) along the wall of each run of door bins a door's width long. Bins
    no pixel falls in (far along the wall, one image column spans several) neither end
    nor break a run; wall bins longer than ``GAP_M`` do."""
    lo = math.floor(float(s.min()) / BIN_M)
    idx = np.floor(s / BIN_M).astype(int) - lo
    total = np.bincount(idx)
    hits = np.bincount(idx, weights=door.astype(float), minlength=len(total))
    seen = np.nonzero(total >= MIN_BIN_PX)[0]
    is_door = hits[seen] >= BIN_DOOR_SHARE * total[seen]
    runs: list[tuple[int, int]] = []
    start = last = None
    gap = GAP_M / BIN_M
    for i, d in zip(seen, is_door, strict=True):
        if d:
            if start is None:
                start = i
            last = i
        elif start is not None and i - last > gap:
            runs.append((start, last))
            start = None
    if start is not None:
        runs.append((start, last))
    out = []
    for a, b in runs:
        length = (b - a + 1) * BIN_M
        if DOOR_WIDTH_M[0] <= length <= DOOR_WIDTH_M[1]:
            out.append(((lo + (a + b + 1) / 2.0) * BIN_M, length))
    return out
