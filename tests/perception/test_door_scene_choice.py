"""Which door a plate belongs to when the view shows one either side (synthetic frames).

A plain wall 2.5 m ahead with a plate at its centre and two brown doors, their frames 0.15 m
from the plate's edges: the scene cannot tell which is the plate's, so the building's
signage mounting decides, else the convention (``grounder.door_side``). A door seen nearer
on one side wins whatever the priors say.
"""

from __future__ import annotations

import numpy as np
import pytest

from pmnav_bt.perception.depth import plate_pose
from pmnav_bt.perception.door_scene import door_for_plate
from pmnav_bt.perception.doors import DoorLayout
from pmnav_bt.sim.textures import make_sign

RANGE = 2.5
DOOR_RGB = (120, 70, 40)


def _frame(wall, near_edges: tuple[float, float]):
    """The plate "112" at the centre; a 1.16 m door from each near edge outwards (m, left
    positive and right negative); returns the frame and the plate's box."""
    obs = wall.frame([("112", 0.0)], range_m=RANGE)
    k = wall.K
    px = k.fx / RANGE
    v_top = int(round(k.cy - (2.18 - obs.camera_height) * px))
    for edge in near_edges:
        far = edge + np.sign(edge) * 1.16
        u0, u1 = sorted(int(round(k.cx - y * px)) for y in (edge, far))
        obs.rgb[max(v_top, 0) :, max(u0, 0) : max(u1, 0)] = DOOR_RGB
    tex = make_sign("112")
    w, h = tex.width_m * px / 2, tex.height_m * px / 2
    return obs, (k.cx - w, k.cy - h, k.cx + w, k.cy + h)


@pytest.mark.parametrize(
    ("prior", "default_side", "door_left"),
    [(None, "left", True), (None, "right", False), ("beside_left", "left", False)],
)
def test_a_tie_is_broken_by_the_priors(wall, prior, default_side, door_left):
    obs, box = _frame(wall, (0.56, -0.56))
    plate = plate_pose(obs, box)
    layout = DoorLayout(default_side=default_side)
    door = door_for_plate(obs, plate, box, layout, prior)
    assert door.seen
    assert (door.centre[1] > 0) == door_left
    assert abs(door.centre[1]) == pytest.approx(0.56 + 0.58, abs=0.12)


def test_the_nearer_door_beats_the_priors(wall):
    obs, box = _frame(wall, (0.8, -0.5))  # the right one starts nearer the plate
    plate = plate_pose(obs, box)
    door = door_for_plate(obs, plate, box, DoorLayout(default_side="left"), "beside")
    assert door.centre[1] == pytest.approx(-(0.5 + 0.58), abs=0.12)


def test_seen_too_near_to_see_above_the_doors_the_wall_is_what_the_plate_hangs_on(wall):
    # 1.2 m from the wall the view ends below the doors' tops, and a leaf fills more of
    # the door band than the wall does: the band's median would be the leaf's colour, and
    # the wall beside the plate a door. The plate's backing says which colour is the wall.
    rng = 1.2
    obs = wall.frame([], range_m=rng)
    k = wall.K
    px = k.fx / rng
    v_top = int(round(k.cy - (2.1 - obs.camera_height) * px))
    obs.rgb[v_top:, : int(round(k.cx + 0.05 * px))] = DOOR_RGB  # the leaf, cut by the view
    x0, x1 = (k.cx + y * px for y in (0.2, 0.35))  # a 0.15 m plate 0.15 m right of it
    y0, y1 = (k.cy - z * px for z in (0.05, -0.05))
    obs.rgb[int(y0) : int(y1), int(x0) : int(x1)] = (30, 30, 34)
    box = (x0, y0, x1, y1)
    door = door_for_plate(obs, plate_pose(obs, box), box, DoorLayout(default_side="right"))
    assert door.seen
    assert door.centre[1] > 0.3  # the leaf's side (where the convention's spot is kept)
