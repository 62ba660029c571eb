"""Where a styled sign plate hangs, and the bodies that show it.

Mountings (``PlateStyle.mounting``), as buildings hang room signs:

- ``beside``: on the wall beside the door at ``height``, on the viewer's right if that
  stretch of wall is free, else on the left (today's plates); ``beside_left`` and
  ``beside_right`` prefer that side. With no room on either side the plate goes above
  the door.
- ``on_door``: on the door leaf, centred, at ``height`` (kept below the leaf's top); an
  open door's leaf stands swung into the room, so its plate hangs beside it (as the twin
  plate buildings put beside doors that stand open).
- ``above_door``: on the wall, centred over the door frame.
- ``flag``: a double-sided plate projecting perpendicular from the wall beside the door,
  its bottom at least ``FLAG_MIN_BOTTOM_M`` above the floor, read end-on from down the
  corridor. Its ``WallItem`` stands in the corridor (the plate's centre), and its normal
  runs along the wall (the face towards +tangent; the other face shows the same plate).

For a flat plate the ``WallItem``'s centre is on the wall surface and its normal the
wall's, as for every other wall item; ``width`` is the plate's with its backing, and
``z`` its bottom and top. Directional signs hang flat on the wall nearest their ``at``.

The builder works on the world through ``SignWorld`` (``SimWorld``'s wall-placement
helpers): this module is the world's signage part, kept apart so that the world file
stays about walls and doors, and it imports nothing of the world (the world imports it).
For that reason the builders return a sign's ``WallItem`` fields (``ItemFields``, in the
class's order) and ``mount_signage`` makes the items with the class the world hands it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from pmnav_bt.map.signage import DirectionalSignSpec, PlateStyle
from pmnav_bt.seams import directional_sign_label, sign_label
from pmnav_bt.sim.scene.plates import make_line_plate, make_plate
from pmnav_bt.sim.scene.signage import BuildingSignage
from pmnav_bt.sim.scene.wayfinding import junction_signs
from pmnav_bt.sim.textures import SignTexture

SIGN_DEPTH = 0.015  # a plate's backing, out of the wall
SIGN_GAP = 0.15  # between a door frame and its sign plate
EDGE_M = 0.01  # the backing shows this much around the printed face
ABOVE_DOOR_GAP_M = 0.08  # between the door frame's top and a plate above it
FLAG_MIN_BOTTOM_M = 2.03  # head clearance under a protruding sign (ADA 307.4: 80 in)
FLAG_STANDOFF_M = 0.05  # bracket: wall to the plate's inner edge
FLAG_OFFSET_M = 0.15  # from the door frame's edge, along the wall, to the flag
DOOR_TOP_MARGIN_M = 0.2  # a door plate's top this far below the frame's (0.12 m under the leaf's)
DIRECTIONAL_Z_M = 1.9  # centre height of a directional sign on the wall


# A WallItem's fields: id, kind, label, centre, normal, width, z (bottom, top), text.
ItemFields = tuple[
    str, str, str, tuple[float, float], tuple[float, float], float, tuple[float, float], str
]


class SignWorld(Protocol):
    """What of ``SimWorld`` the signs are built with (see sim/world.py for each)."""

    building: Any
    walls: list  # WallSegment
    annotated_walls: int  # walls[:annotated_walls] bound the corridors; the rest hang items
    doors: dict  # room id -> WallItem
    signs: dict
    directional_signs: dict
    _where: dict  # label -> (wall index, position along it)
    door_states: dict[str, Any]  # room -> sim.scene.doors.DoorState

    def label_id(self, label: str) -> int: ...
    def rng(self, part: str) -> np.random.Generator: ...
    def ray(self, start: tuple, end: tuple) -> Any: ...
    def add_box(self, centre, half_extents, yaw, rgba, label, *, solid=True, collision=None): ...
    def _snap(self, what: str, pt: tuple[float, float], half: float) -> tuple[int, float]: ...
    def _fits(self, wall: int, s0: float, s1: float) -> bool: ...
    def _occupy(self, wall: int, s: float, half: float) -> None: ...
    def _wall_box(self, wall, s, depth, width, z0, z1, rgba, label, *, solid=True, out=0.0): ...
    def _add_textured_quad(self, centre, normal, width, height, image, label) -> int: ...


def _shade(rgb: tuple[int, int, int], k: float) -> tuple[float, float, float, float]:
    """The backing's colour: the plate's, darkened by ``k``."""
    return (*(k * c / 255.0 for c in rgb), 1.0)


def mount_signage(world: SignWorld, signage: BuildingSignage, item: Callable[..., Any]) -> None:
    """Build every room sign of ``world`` in its style, and the directional signs: the
    file's, or with random signage and none in the file, the junctions' (wayfinding.py);
    ``item`` makes a WallItem of its fields (``ItemFields``)."""
    for room in world.building.rooms:
        style = signage.rooms[room.id]
        world.signs[room.id] = item(*mount_room_sign(world, room.id, room.sign_text, style))
    directional = signage.directional
    if not directional and signage.wayfinding:
        directional = junction_signs(
            world.building, world.walls[: world.annotated_walls], world.rng("wayfinding")
        )
    for i, spec in enumerate(directional):
        world.label_id(directional_sign_label(i))
        fields = mount_directional_sign(world, i, spec, signage.style)
        world.directional_signs[str(i)] = item(*fields)


def mount_room_sign(world: SignWorld, room_id: str, text: str, style: PlateStyle) -> ItemFields:
    """Build the sign of ``room_id`` (reading ``text``) in ``style`` beside its door."""
    door = world.doors[room_id]
    wi, s_door = world._where[door.label]
    tex = make_plate(text, style)
    label = sign_label(room_id)
    if style.mounting == "flag":
        return _flag(world, door, wi, s_door, tex, style, label)
    w, h = tex.width_m + 2 * EDGE_M, tex.height_m + 2 * EDGE_M
    out = 0.0
    mounting = style.mounting
    state = world.door_states.get(room_id)
    if mounting == "on_door" and state is not None and state.open:
        mounting = "beside"  # the leaf stands swung into the room: its twin plate beside it
    if mounting == "on_door":
        s = s_door
        z = min(style.height, door.z[1] - DOOR_TOP_MARGIN_M - h / 2.0)
        out = _leaf_out(world, door, wi, s, z)
    elif mounting == "above_door":
        s, z = s_door, _above(world, door, h)
    else:
        off = door.width / 2 + SIGN_GAP + w / 2
        right, left = s_door - off, s_door + off
        order = (left, right) if mounting == "beside_left" else (right, left)
        for s in order:  # -s is the viewer's right
            if world._fits(wi, s - w / 2, s + w / 2):
                world._occupy(wi, s, w / 2)
                z = style.height
                break
        else:
            s, z = s_door, _above(world, door, h)
    return _flat(world, wi, s, z, out, tex, style, label, room_id, "sign")


def mount_directional_sign(
    world: SignWorld, index: int, spec: DirectionalSignSpec, style: PlateStyle
) -> ItemFields:
    """Build directional sign ``index`` on the wall nearest ``spec.at``, in the building's
    colours and font."""
    tex = make_line_plate(spec.text, style)
    w = tex.width_m + 2 * EDGE_M
    wi, s = world._snap(f"directional sign {spec.text!r}", spec.at, w / 2)
    label = directional_sign_label(index)
    return _flat(world, wi, s, DIRECTIONAL_Z_M, 0.0, tex, style, label, str(index), "directional")


def _leaf_out(world: SignWorld, door, wi: int, s: float, z: float) -> float:
    """How far the door's leaf stands out of the wall at ``s``, height ``z`` (0 if the
    leaf is not there): a door plate is fixed on its face."""
    wall = world.walls[wi]
    n = np.asarray(wall.normal)
    p = wall.point(s)
    hit = world.ray((*(p + n), z), (*(p - 0.05 * n), z))
    return max(0.0, 1.0 - hit.distance) if hit is not None and hit.label == door.label else 0.0


def _above(world: SignWorld, door, h: float) -> float:
    """Centre height of a plate ``h`` tall over the door, kept under the ceiling."""
    z = door.z[1] + ABOVE_DOOR_GAP_M + h / 2.0
    return min(z, world.building.wall_height - 0.02 - h / 2.0)


def _flat(
    world: SignWorld,
    wi: int,
    s: float,
    z: float,
    out: float,
    tex: SignTexture,
    style: PlateStyle,
    label: str,
    ident: str,
    kind: str,
) -> ItemFields:
    """A plate flat on wall ``wi`` at ``s``, centred at height ``z``, ``out`` metres in
    front of the wall (a door leaf's thickness for door plates)."""
    w, h = tex.width_m + 2 * EDGE_M, tex.height_m + 2 * EDGE_M
    wall = world.walls[wi]
    n = np.asarray(wall.normal)
    z0, z1 = z - h / 2.0, z + h / 2.0
    world._wall_box(wi, s, SIGN_DEPTH, w, z0, z1, _shade(style.plate_rgb, 0.6), label, out=out)
    face = np.append(wall.point(s) + n * (out + SIGN_DEPTH + 0.002), z)
    world._add_textured_quad(face, n, tex.width_m, tex.height_m, tex.image, label)
    c = wall.point(s)
    centre = (float(c[0]), float(c[1]))
    return ident, kind, label, centre, wall.normal, w, (z0, z1), tex.text


def _flag(
    world: SignWorld,
    door,
    wi: int,
    s_door: float,
    tex: SignTexture,
    style: PlateStyle,
    label: str,
) -> ItemFields:
    """A double-sided plate sticking out of the wall beside the door's frame."""
    wall = world.walls[wi]
    n, t = np.asarray(wall.normal), wall.tangent
    w, h = tex.width_m + 2 * EDGE_M, tex.height_m + 2 * EDGE_M
    z = max(style.height, FLAG_MIN_BOTTOM_M + h / 2.0)
    z = min(z, world.building.wall_height - 0.02 - h / 2.0)
    s = s_door - (door.width / 2.0 + FLAG_OFFSET_M)  # the viewer's right of the door
    if s < 0.0:  # the wall ends there: the other side
        s = s_door + door.width / 2.0 + FLAG_OFFSET_M
    base = wall.point(s)
    centre = base + n * (FLAG_STANDOFF_M + w / 2.0)
    yaw = math.atan2(n[1], n[0])
    world.add_box(
        (float(centre[0]), float(centre[1]), z),
        (w / 2.0, SIGN_DEPTH / 2.0, h / 2.0),
        yaw,
        _shade(style.plate_rgb, 0.6),
        label,
        solid=False,
        collision=True,
    )
    bracket = base + n * (FLAG_STANDOFF_M / 2.0)
    world.add_box(
        (float(bracket[0]), float(bracket[1]), z + h / 2.0 - 0.02),
        (FLAG_STANDOFF_M / 2.0 + 0.01, 0.01, 0.01),
        yaw,
        (0.3, 0.3, 0.32, 1.0),
        label,
        solid=False,
        collision=False,
    )
    for side in (1.0, -1.0):
        face = np.append(centre + side * t * (SIGN_DEPTH / 2.0 + 0.002), z)
        world._add_textured_quad(face, side * t, tex.width_m, tex.height_m, tex.image, label)
    return (
        door.id,
        "sign",
        label,
        (float(centre[0]), float(centre[1])),
        (float(t[0]), float(t[1])),
        w,
        (z - h / 2.0, z + h / 2.0),
        tex.text,
    )
