"""Doors seen along the walls, in the simulator's views (320x240, as the tree's)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.geometry import se2_apply
from pmnav_bt.perception.depth import surfaces
from pmnav_bt.perception.door_sightings import find_doors
from pmnav_bt.seams import Pose2D

pytest.importorskip("pybullet")


def doors_seen(world, x: float, y: float, yaw_deg: float) -> np.ndarray:
    """(K, 2) map xy of the doors found in the view from (x, y, yaw_deg)."""
    from pmnav_bt.sim.robot import SimBase

    pose = (x, y, math.radians(yaw_deg))
    base = SimBase(world, pose=Pose2D(*pose), width=320, height=240)
    try:
        obs = base.observe()
        found = find_doors(obs, surfaces(obs).wall)
    finally:
        base.close()
    return np.array([se2_apply(pose, d.centre) for d in found]).reshape(-1, 2)


def door_xy(world, room: str) -> np.ndarray:
    return np.asarray(world.doors[room].centre)


@pytest.fixture(scope="module")
def sparse():
    from pmnav_bt.sim.world import SimWorld

    with SimWorld("sign_sparse_2") as world:
        yield world


@pytest.fixture(scope="module")
def office():
    from pmnav_bt.sim.world import SimWorld

    with SimWorld("straight_office") as world:
        yield world


def test_doors_far_beyond_their_signs_are_found_where_they_are(sparse):
    # 13 m east of branch1, looking west: room9's door 4.5 m ahead, room8's 7.5 m and
    # room7's 10.5 m (their signs are read from 3.5 m at most).
    got = doors_seen(sparse, 15.0, 30.0, 180.0)
    assert len(got) == 3
    for room in ("room7", "room8", "room9"):
        assert np.min(np.linalg.norm(got - door_xy(sparse, room), axis=1)) < 0.3, room


def test_a_bare_corridor_shows_no_door(sparse):
    for pose in ((30.0, 45.0, 90.0), (30.0, 45.0, -90.0), (45.0, 30.0, 0.0)):
        assert len(doors_seen(sparse, *pose)) == 0, pose


def test_a_row_of_doors_is_told_door_by_door(office):
    # Doors on both walls every 3.5 m: at door height they fill more of the wall than the
    # wall does, so the wall's colour is taken above them (a median at door height was
    # a door's colour, and the wall between two doors was "found" instead).
    got = doors_seen(office, 23.0, 0.0, 180.0)
    doors = np.array([d.centre for d in office.doors.values()])
    assert len(got) >= 6
    for g in got:
        assert np.min(np.linalg.norm(doors - g, axis=1)) < 0.3, g


def test_no_depth_or_no_wall_finds_nothing(sparse):
    from pmnav_bt.sim.robot import SimBase

    base = SimBase(sparse, pose=Pose2D(15.0, 30.0, math.pi), width=320, height=240)
    try:
        obs = base.observe()
    finally:
        base.close()
    assert find_doors(obs, np.zeros(obs.rgb.shape[:2], bool)) == []
    from dataclasses import replace

    assert find_doors(replace(obs, depth=None), surfaces(obs).wall) == []


def test_the_ends_of_staggered_wall_boxes_are_not_doors():
    """The real-map hospital with walls from its occupancy grid: the left wall north of
    (-6, -7.6) is a row of staggered boxes whose ends, facing along the corridor, are
    shaded darker; they were found as two doors 6-8 m ahead where there is none."""
    from pathlib import Path

    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.sim.world import SimWorld

    here = Path(__file__).resolve().parents[2] / "examples" / "hospital"
    building = load_building(here / "building.yaml")
    with SimWorld(building, walls="grid", base_dir=here) as world:
        got = doors_seen(world, -6.0, -7.6, 90.0)
        doors = np.array([d.centre for d in world.doors.values()])
    for g in got:
        assert np.min(np.linalg.norm(doors - g, axis=1)) < 0.6, g
