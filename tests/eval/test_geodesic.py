"""The free-space geodesic on hand cases: straight and L-shaped corridors, obstacles."""

from __future__ import annotations

import math

import pytest
from shapely.geometry import LineString, box

from pmnav_bt.eval.geodesic import GeodesicError, GeodesicField
from pmnav_bt.seams import CREATE3_RADIUS_M

R = CREATE3_RADIUS_M


def test_straight_corridor_is_the_straight_line_to_the_disc():
    field = GeodesicField(box(0, -1, 20, 1), (15.0, 0.0), 1.0)
    assert field.distance((2.0, 0.0)) == pytest.approx(12.0, abs=0.02)
    assert field.distance((14.5, 0.3)) == 0.0  # inside the disc
    assert field.distance((17.0, 0.0)) == pytest.approx(1.0, abs=0.02)


def test_l_corridor_goes_round_the_eroded_inner_corner():
    corridor = box(0, -1, 10, 1).union(box(8, -1, 10, 10))
    field = GeodesicField(corridor, (9.0, 9.0), 1.0)
    corner = (8.0 + R, 1.0 - R)  # the inner corner, pushed out by the robot's radius
    exact = math.dist((1.0, 0.0), corner) + math.dist(corner, (9.0, 9.0)) - 1.0
    assert field.distance((1.0, 0.0)) == pytest.approx(exact, rel=0.005)
    # Shorter than the walk along the centre lines (to the disc), longer than the crow flies.
    assert field.distance((1.0, 0.0)) < 8.0 + 8.0
    path = field.path((1.0, 0.0))
    assert LineString(path).length == pytest.approx(exact, rel=0.01)
    assert math.dist(path[-1], (9.0, 9.0)) <= 1.0 + 0.02
    # The path keeps the body's radius from the walls, less the grid's 5 cm.
    assert corridor.buffer(-(R - 0.06)).contains(LineString(path))


def test_obstacles_lengthen_the_way_and_walls_block_it():
    corridor = box(0, -1, 20, 1)
    free = GeodesicField(corridor, (15.0, 0.0), 1.0)
    blocked = GeodesicField(corridor, (15.0, 0.0), 1.0, obstacles=[box(7, -1, 8, 0.3)])
    a, b = (7.0 - R, 0.3 + R), (8.0 + R, 0.3 + R)  # round the obstacle's eroded corners
    exact = math.dist((2.0, 0.0), a) + math.dist(a, b) + math.dist(b, (15.0, 0.0)) - 1.0
    assert blocked.distance((2.0, 0.0)) == pytest.approx(exact, rel=0.002)
    assert blocked.distance((2.0, 0.0)) > free.distance((2.0, 0.0)) + 0.03
    wall = GeodesicField(corridor, (15.0, 0.0), 1.0, obstacles=[box(7, -1, 8, 1)])
    assert math.isinf(wall.distance((2.0, 0.0)))
    with pytest.raises(GeodesicError, match="no drivable point"):
        GeodesicField(corridor, (15.0, 5.0), 1.0)
