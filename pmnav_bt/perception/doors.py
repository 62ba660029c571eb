"""A room's door from its sign by one convention: the door is where the building puts it.

This is the prior ``door_scene.door_for_plate`` falls back to when it sees no door near a
read plate, and keeps where the door it sees confirms it (docs/perception.md, "From a
sign to its door").

A door sign hangs on the wall beside its door, at a known centre-to-centre distance
(``sign_to_door``, a building convention: 1.14 m in the simulator, a 1.16 m door frame,
a 0.15 m gap and a 0.82 m plate). Depth gives the plate's centre and the wall's
direction; the door's centre is ``sign_to_door`` along the wall on one side of it. The
side is read from the image: the wall right below the sign is the reference, and the
side whose door-height patch looks least like that wall (colour, in CIELAB) is the door;
a patch that is not on the wall's plane (an opening, a junction) cannot be the door.
When neither side can be told (both out of view, or both look like wall) the building's
convention ``default_side`` decides (the simulator hangs signs on the viewer's right of
their door, so the door is on the ``left`` of the sign unless the wall ends there).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import cv2
import numpy as np

from pmnav_bt.perception.depth import PlatePose, back_project, polygon_mask, wall_rect
from pmnav_bt.seams import Observation

Side = Literal["left", "right"]
MIN_PATCH_PX = 12  # pixels a patch needs in view to be compared
MIN_DOOR_CONTRAST = 12.0  # CIELAB distance between a door patch and the wall
ON_WALL = 0.25  # m from the wall plane for a patch pixel to be on the wall


@dataclass(frozen=True)
class DoorLayout:
    """Where doors are relative to their signs, and how big they are (metres)."""

    sign_to_door: float = 1.14
    door_width: float = 1.16
    door_height: float = 2.18
    default_side: Side = "left"


@dataclass(frozen=True)
class DoorEstimate:
    """A door derived from its sign: centre (camera body frame, mid-height), where it is
    from the sign (on its ``left`` or ``right``, or ``at`` it: the plate on or above the
    door), whether the image told that, and its image mask (None: out of view)."""

    centre: np.ndarray
    side: Side | Literal["at"]
    seen: bool
    mask: np.ndarray | None


def door_from_sign(obs: Observation, plate: PlatePose, layout: DoorLayout) -> DoorEstimate:
    """The door beside the sign ``plate`` (see the module docstring)."""
    cam_h = obs.camera_height
    floor_z = -cam_h
    z_band = (floor_z + 0.85, floor_z + 1.25)  # below the sign, door-handle height
    lab = cv2.cvtColor(obs.rgb, cv2.COLOR_RGB2LAB).astype(np.float32)
    pts = back_project(obs)

    def patch(centre: np.ndarray, half: float) -> tuple[np.ndarray, float] | None:
        m = polygon_mask(obs, wall_rect(centre, plate.left, half, *z_band))
        if m is None or m.sum() < MIN_PATCH_PX:
            return None
        off = np.abs((pts[m] - plate.centre) @ plate.normal)
        on_wall = float(np.mean(np.nan_to_num(off, nan=1e9) < ON_WALL))
        return lab[m].mean(axis=0), on_wall

    ref = patch(plate.centre, 0.25)
    scores: dict[Side, float] = {}
    for side, sgn in (("left", 1.0), ("right", -1.0)):
        c = plate.centre + sgn * layout.sign_to_door * plate.left
        p = patch(c, 0.35)
        if p is None or ref is None:
            continue
        colour, on_wall = p
        if on_wall < 0.5:
            scores[side] = -1.0  # not on the wall: an opening, not a door
        else:
            scores[side] = float(np.linalg.norm(colour - ref[0]))
    side, seen = _choose(scores, layout.default_side)
    return door_beside(obs, plate, layout, side, seen)


def door_beside(
    obs: Observation, plate: PlatePose, layout: DoorLayout, side: Side, seen: bool
) -> DoorEstimate:
    """The door ``sign_to_door`` on ``side`` of the sign ``plate``, at mid-height, with its
    image mask; ``seen``: whether the image told the side."""
    floor_z = -obs.camera_height
    sgn = 1.0 if side == "left" else -1.0
    centre = plate.centre + sgn * layout.sign_to_door * plate.left
    centre = np.array([centre[0], centre[1], floor_z + layout.door_height / 2.0])
    m = polygon_mask(
        obs,
        wall_rect(
            centre, plate.left, layout.door_width / 2.0, floor_z, floor_z + layout.door_height
        ),
    )
    if m is not None and not m.any():
        m = None
    return DoorEstimate(centre, side, seen, m)


def _choose(scores: dict[Side, float], default: Side) -> tuple[Side, bool]:
    other: Side = "right" if default == "left" else "left"
    doorish = {s for s, v in scores.items() if v >= MIN_DOOR_CONTRAST}
    if len(doorish) == 2:
        return max(doorish, key=lambda s: scores[s]), True
    if len(doorish) == 1:
        return next(iter(doorish)), True
    # No side looks like a door: a side seen to be plain wall or an opening is not it.
    if default in scores and other not in scores:
        return other, True
    return default, False
