"""Where to stand to read a plate seen but not read: square to it, within the range its
text size allows, on free floor; and the table that range comes from."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.perception.read_range import PlateRanges, shipped_plate_ranges
from pmnav_bt.perception.reading_pose import (
    CLOSER_M,
    MIN_STANDOFF_M,
    RANGE_MARGIN_M,
    VIEW_MARGIN,
    reading_pose,
    view_standoff,
)
from pmnav_bt.perception.unread_plates import unread_plate

# A wall running at 30 deg through the origin; the corridor is the 2.4 m in front of it.
WALL = math.radians(30.0)
ALONG = np.array([math.cos(WALL), math.sin(WALL)])
NORMAL = np.array([-math.sin(WALL), math.cos(WALL)])
WIDTH = 2.4
PLATE = (0.0, 0.0)


def in_corridor(p, margin: float = 0.3) -> bool:
    off = float(np.asarray(p) @ NORMAL)
    return margin <= off <= WIDTH - margin


def seen_aslant() -> tuple[float, float]:
    """Where the robot saw the plate from: 5 m along the wall, on the centre line."""
    q = 5.0 * ALONG + 1.2 * NORMAL
    return float(q[0]), float(q[1])


def test_a_plate_seen_aslant_is_read_square_to_it_at_its_range_on_free_floor():
    seen = seen_aslant()
    pose = reading_pose(PLATE, tuple(NORMAL), 2.2, in_corridor, seen_from=seen, robot=seen)
    assert pose is not None and pose.angle == 0.0
    spot = np.array([pose.x, pose.y])
    # on the plate's normal, within the range (less its margin), inside the corridor
    assert abs(float(spot @ ALONG)) < 1e-9
    assert pose.distance == pytest.approx(float(spot @ NORMAL))
    assert MIN_STANDOFF_M <= pose.distance <= 2.2 - RANGE_MARGIN_M + 1e-9
    assert in_corridor(spot)
    # facing the plate
    to_plate = math.atan2(-pose.y, -pose.x)
    assert abs(math.remainder(pose.yaw - to_plate, math.tau)) < 1e-9
    # of the spots on the normal, the one nearest the robot (on the centre line, 1.2 m out)
    assert abs(pose.distance - 1.2) <= 0.1 + 1e-9


def test_something_standing_on_the_normal_moves_the_spot_aside_not_out_of_range():
    seen = seen_aslant()

    def free(p) -> bool:  # a cart on the plate's normal, 0.4 m each side of it
        return in_corridor(p) and abs(float(np.asarray(p) @ ALONG)) > 0.4

    pose = reading_pose(PLATE, tuple(NORMAL), 2.2, free, seen_from=seen, robot=seen)
    assert pose is not None and pose.angle != 0.0 and abs(math.degrees(pose.angle)) <= 45.0
    assert free((pose.x, pose.y)) and pose.distance <= 2.2 - RANGE_MARGIN_M + 1e-9
    assert pose.distance == pytest.approx(math.hypot(pose.x, pose.y))


def test_a_plate_not_read_from_within_its_range_is_read_from_nearer():
    seen = tuple(1.5 * NORMAL)  # square to it, 1.5 m off: inside the 2.2 m range
    pose = reading_pose(PLATE, tuple(NORMAL), 2.2, in_corridor, seen_from=seen, robot=seen)
    assert pose is not None and pose.distance <= 1.5 - CLOSER_M + 1e-9


def test_a_high_plate_is_not_stood_under():
    vfov = math.radians(47.0)
    near = view_standoff(2.4, 1.6, vfov)  # a flag sign 0.8 m above the camera
    assert near > 1.5 and view_standoff(1.5, 1.6, vfov) == 0.0
    seen = seen_aslant()
    pose = reading_pose(PLATE, tuple(NORMAL), 1.0, in_corridor, seen_from=seen, robot=seen,
                        nearest=near)  # fmt: skip
    assert pose is not None and pose.distance >= near


def test_a_flag_is_read_from_where_its_text_stays_in_view_not_its_guessed_plate():
    # A flag's small text is read only between where it leaves the top of the view and
    # where it grows too small: the standoff is where the text's top, as depth measured
    # it, is VIEW_MARGIN inside the view's top, whatever the plate's size.
    vfov = math.radians(47.0)
    top = 2.35
    near = view_standoff(top, 1.6, vfov)
    assert math.atan2(top - 1.6, near) == pytest.approx(vfov / 2.0 - VIEW_MARGIN)


def test_an_unread_plate_knows_its_texts_top(wall):
    # A plate's text 2.25-2.35 m above the floor on the wall 1.8 m ahead (camera 1.6 m):
    # its top is measured from the box at the plate's depth, not guessed from its centre.
    obs = wall.frame([], range_m=1.8)
    k = wall.K
    px = k.fy / 1.8
    box = (150.0, k.cy - 0.75 * px, 170.0, k.cy - 0.65 * px)
    plate = unread_plate(obs, box, 0.08 * px)
    assert plate is not None
    assert plate.z == pytest.approx(2.3, abs=0.02)
    assert plate.top == pytest.approx(2.35, abs=0.02)


def test_no_free_spot_no_pose():
    pose = reading_pose(PLATE, tuple(NORMAL), 2.2, lambda p: False, seen_from=seen_aslant(),
                        robot=seen_aslant())  # fmt: skip
    assert pose is None


def counts(rows: dict[float, list[int]], width: int = 640, views: int = 10) -> dict:
    """A sign_ranges table: one font, capital height -> reads of ``views`` per band."""
    bands = [[0.75, 1.25], [1.25, 1.75], [1.75, 2.5], [2.5, 3.5]]
    return {
        "bands_m": bands,
        "cells": [
            {"font": "f", "cap_height_m": cap, "width": width, "views": [views] * 4,
             "reads": reads, "line_height_m": 1.2 * cap}
            for cap, reads in rows.items()
        ],
    }  # fmt: skip


def test_the_read_range_grows_with_the_text_and_the_camera():
    t = PlateRanges.from_counts(counts({0.03: [10, 8, 5, 0], 0.06: [10, 10, 9, 8]}))
    small, large = 1.2 * 0.03, 1.2 * 0.06
    assert t.read_range(640, small) == pytest.approx(1.75)  # recall 0.8 to the second band
    assert t.read_range(640, large) == pytest.approx(3.5)
    assert small < 0.045 < large and 1.75 < t.read_range(640, 0.045) < 3.5  # between rows
    assert t.read_range(320, large) < t.read_range(640, large)  # fewer pixels on the text
    assert t.read_range(640, small / 2) < t.read_range(640, small)
    assert t.read_range(640, large, recall=0.5) >= t.read_range(640, large)


def test_the_shipped_table_reads_larger_plates_from_farther():
    t = shipped_plate_ranges()
    assert sorted(t.rows) and all(len(r) >= 2 for r in t.rows.values())
    lines = [h for h, _ in t.rows[max(t.rows)]]
    assert t.read_range(640, lines[0]) <= t.read_range(640, lines[-1])


def test_a_line_lower_than_any_plates_text_is_no_unread_plate(wall):
    # A door's lintel or frame edge closes into a "line" of a centimetre or so; a room
    # plate's text line is at least 1.3 x its 20 mm capitals. Same box, two line heights.
    obs = wall.frame([], range_m=1.8)
    k = wall.K
    px = k.fy / 1.8
    box = (150.0, k.cy - 0.75 * px, 170.0, k.cy - 0.65 * px)
    assert unread_plate(obs, box, 0.015 * px) is None
    assert unread_plate(obs, box, 0.03 * px) is not None


def test_a_read_plates_top_is_its_texts_not_its_borders(wall):
    # The finder's box takes in the plate's border (2.35 m); the text read inside it starts
    # lower (2.31 m): the standoff a high plate needs is from the text's top.
    obs = wall.frame([], range_m=1.8)
    k = wall.K
    px = k.fy / 1.8
    box = (150.0, k.cy - 0.75 * px, 170.0, k.cy - 0.65 * px)
    plate = unread_plate(obs, box, 0.08 * px, "2O9", text_top_px=k.cy - 0.71 * px)
    assert plate is not None and plate.top == pytest.approx(2.31, abs=0.02)
