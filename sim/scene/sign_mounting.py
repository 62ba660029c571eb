"""Where a styled sign plate hangs, and the bodies that show it.

Mountings (``PlateStyle.mounting``), as buildings hang room signs:

- ``beside``: on the wall beside the door at ``height``, on the viewer's right if that
  stretch of wall is free, else on the left (today's plates); ``beside_left`` and
  ``beside_right`` prefer that side. With no room on either side the plate goes above
  the door.
- ``on_door``: on the door leaf, centred, at ``height`` (kept below the leaf's top).
- ``above_door``: on the wall, centred over the door frame.
- ``flag``: a double-sided plate projecting perpendicular from the wall beside the door,
  its bottom at least ``FLAG_MIN_BOTTOM_M`` above the floor, read end-on from down the
  corridor. Its ``WallItem`` stands in the corridor (the plate's centre), and its normal
  runs along the wall (the face towards +tangent; the other face shows the same plate).

For a flat plate the ``WallItem``'s centre is on the wall surface and its normal the
wall's, as for every other wall item; ``width`` is the plate's with its backing, and
``z`` its bottom and top. Directional signs hang flat on the wall nearest their ``at``.

The builder uses the world's wall-placement helpers (``_snap``, ``_fits``, ``_occupy``,
``_wall_box``, ``_add_textured_quad``): this module is the world's signage part, kept
apart so that the world file stays about walls and doors.
"""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.map.signage import DirectionalSignSpec, PlateStyle
from pmnav_bt.seams import directional_sign_label, sign_label
from pmnav_bt.sim.scene.plates import make_line_plate, make_plate
from pmnav_bt.sim.scene.signage import BuildingSignage
from pmnav_bt.sim.scene.wayfinding import junction_signs
from pmnav_bt.sim.textures import SignTexture
from pmnav_bt.sim.world import (
    DOOR_HEIGHT,
    PANEL_DEPTH,
    SIGN_DEPTH,
    SIGN_GAP,
    SimWorld,
    WallItem,
)

EDGE_M = 0.01  # the backing shows this much around the printed face
ABOVE_DOOR_GAP_M = 0.08  # between the door frame's top and a plate above it
FLAG_MIN_BOTTOM_M = 2.03  # head clearance under a protruding sign (ADA 307.4: 80 in)
FLAG_STANDOFF_M = 0.05  # bracket: wall to the plate's inner edge
FLAG_OFFSET_M = 0.15  # from the door frame's edge, along the wall, to the flag
DOOR_TOP_MARGIN_M = 0.1  # a door plate's top stays this far below the leaf's top
DIRECTIONAL_Z_M = 1.9  # centre height of a directional sign on the wall


def _shade(rgb: tuple[int, int, int], k: float) -> tuple[float, float, float, float]:
    """The backing's colour: the plate's, darkened by ``k``."""
    return (*(k * c / 255.0 for c in rgb), 1.0)


def mount_signage(world: SimWorld, signage: BuildingSignage) -> None:
    """Build every room sign of ``world`` in its style, and the directional signs: the
    file's, or with random signage and none in the file, the junctions' (wayfinding.py)."""
    for room in world.building.rooms:
        style = signage.rooms[room.id]
        world.signs[room.id] = mount_room_sign(world, room.id, room.sign_text, style)
    directional = signage.directional
    if not directional and signage.wayfinding:
        directional = junction_signs(world.building, world.walls, world.rng("wayfinding"))
    for i, spec in enumerate(directional):
        world.label_id(directional_sign_label(i))
        world.directional_signs[str(i)] = mount_directional_sign(world, i, spec, signage.style)


def mount_room_sign(world: SimWorld, room_id: str, text: str, style: PlateStyle) -> WallItem:
    """Build the sign of ``room_id`` (reading ``text``) in ``style`` beside its door."""
    door = world.doors[room_id]
    wi, s_door = world._where[door.label]
    tex = make_plate(text, style)
    label = sign_label(room_id)
    if style.mounting == "flag":
        return _flag(world, door, wi, s_door, tex, style, label)
    w, h = tex.width_m + 2 * EDGE_M, tex.height_m + 2 * EDGE_M
    out = 0.0
    if style.mounting == "on_door":
        s = s_door
        z = min(style.height, DOOR_HEIGHT - DOOR_TOP_MARGIN_M - h / 2.0)
        out = PANEL_DEPTH
    elif style.mounting == "above_door":
        s, z = s_door, _above(world, door, h)
    else:
        off = door.width / 2 + SIGN_GAP + w / 2
        right, left = s_door - off, s_door + off
        order = (left, right) if style.mounting == "beside_left" else (right, left)
        for s in order:  # -s is the viewer's right
            if world._fits(wi, s - w / 2, s + w / 2):
                world._occupy(wi, s, w / 2)
                z = style.height
                break
        else:
            s, z = s_door, _above(world, door, h)
    return _flat(world, wi, s, z, out, tex, style, label, room_id, "sign")


def mount_directional_sign(
    world: SimWorld, index: int, spec: DirectionalSignSpec, style: PlateStyle
) -> WallItem:
    """Build directional sign ``index`` on the wall nearest ``spec.at``, in the building's
    colours and font."""
    tex = make_line_plate(spec.text, style)
    w = tex.width_m + 2 * EDGE_M
    wi, s = world._snap(f"directional sign {spec.text!r}", spec.at, w / 2)
    label = directional_sign_label(index)
    return _flat(world, wi, s, DIRECTIONAL_Z_M, 0.0, tex, style, label, str(index), "directional")


def _above(world: SimWorld, door: WallItem, h: float) -> float:
    """Centre height of a plate ``h`` tall over the door, kept under the ceiling."""
    z = door.z[1] + ABOVE_DOOR_GAP_M + h / 2.0
    return min(z, world.building.wall_height - 0.02 - h / 2.0)


def _flat(
    world: SimWorld,
    wi: int,
    s: float,
    z: float,
    out: float,
    tex: SignTexture,
    style: PlateStyle,
    label: str,
    ident: str,
    kind: str,
) -> WallItem:
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
    return WallItem(ident, kind, label, centre, wall.normal, w, (z0, z1), tex.text)


def _flag(
    world: SimWorld,
    door: WallItem,
    wi: int,
    s_door: float,
    tex: SignTexture,
    style: PlateStyle,
    label: str,
) -> WallItem:
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
    return WallItem(
        door.id,
        "sign",
        label,
        (float(centre[0]), float(centre[1])),
        (float(t[0]), float(t[1])),
        w,
        (z - h / 2.0, z + h / 2.0),
        tex.text,
    )
