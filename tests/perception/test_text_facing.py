"""Which way an unread plate's text faces: the wall's normal, unless its text was read
more aslant than a flat plate is ever read (a flag sign across the wall)."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.perception.unread_plates import FLAT_READ_DEG, text_facing

WALL_NORMAL = (0.0, -1.0)  # camera body frame: a wall on the left, its normal to the right


def seen_at(deg: float, dist: float = 2.0) -> tuple[float, float]:
    """A plate's centre (camera body frame) seen ``deg`` off the wall's normal."""
    a = math.radians(deg)
    # the camera at the origin; the plate at -dist along the direction deg off the normal
    return (dist * math.sin(a), dist * math.cos(a))


def test_a_plate_read_within_the_flat_range_faces_its_walls_normal():
    for deg in (0.0, 40.0, FLAT_READ_DEG - 1.0):
        assert text_facing(seen_at(deg), WALL_NORMAL, read=True) == pytest.approx(WALL_NORMAL)


def test_text_read_beyond_the_flat_range_faces_along_the_wall_towards_the_camera():
    for deg in (FLAT_READ_DEG + 1.0, 85.0):
        centre = seen_at(deg)
        f = text_facing(centre, WALL_NORMAL, read=True)
        assert abs(f[0] * WALL_NORMAL[0] + f[1] * WALL_NORMAL[1]) == pytest.approx(0.0)
        assert -(f[0] * centre[0] + f[1] * centre[1]) > 0.0  # towards the camera


def test_a_plate_nothing_was_read_of_keeps_the_walls_normal():
    assert text_facing(seen_at(85.0), WALL_NORMAL, read=False) == pytest.approx(WALL_NORMAL)


def test_a_flag_depth_shows_across_its_wall_faces_along_it_read_or_not():
    # Depth's normal of a flag seen end-on may be anything (here 70 deg off the view:
    # within the flat range); the wall fit says it stands across the wall.
    centre = seen_at(70.0)
    wall_dir = (1.0, 0.0)  # the wall's direction (door_scene.plate_wall's ``left``)
    for read in (True, False):
        f = text_facing(centre, WALL_NORMAL, read=read, across=wall_dir)
        assert abs(f[1]) == pytest.approx(0.0)
        assert -(f[0] * centre[0] + f[1] * centre[1]) > 0.0
