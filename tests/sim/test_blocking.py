"""An episode may ask for a closed corridor: a barrier from wall to wall at a segment."""

import dataclasses
import math

import numpy as np
import pytest

from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import CREATE3_RADIUS_M
from pmnav_bt.sim.episodes import (
    Episode,
    EpisodeFileError,
    goal_geodesic,
    load_episodes,
    save_episodes,
)
from pmnav_bt.sim.robot import COLLISION_HEIGHT
from pmnav_bt.sim.scene.blocking import BlockError, block_segment
from pmnav_bt.sim.world import SimWorld


@pytest.fixture(scope="module")
def office():
    b = load_building("straight_office")
    return b, parse_building(b)


def test_a_blocked_segment_closes_the_corridor_from_wall_to_wall(office):
    b, pm = office
    with SimWorld(b, ceiling=False) as world:
        seg = pm.segment("seg4")
        a, c = pm.node_xy(seg.a), pm.node_xy(seg.b)
        mid, along = (a + c) / 2, (c - a) / np.linalg.norm(c - a)
        across = np.array([-along[1], along[0]])
        for t in (-0.8, 0.0, 0.8):
            assert world.clearance(*(mid + across * t), CREATE3_RADIUS_M) >= 0
        block_segment(world, pm, "seg4")
        for t in np.linspace(-1.0, 1.0, 9):  # nowhere across the corridor to slip through
            assert world.clearance(*(mid + across * t), CREATE3_RADIUS_M) < 0
        floor = world.floor_space()
        solid = world.obstacle_footprints(COLLISION_HEIGHT)
        field = goal_geodesic(pm, "room6", solid, floor=floor)
        assert math.isinf(field.distance(tuple(a - along * 2)))  # room6 lies beyond it
        assert math.isfinite(field.distance(tuple(c + along * 2)))


def test_an_unknown_segment_is_one_clear_error(office):
    b, pm = office
    with SimWorld(b, ceiling=False) as world, pytest.raises(BlockError, match="seg999"):
        block_segment(world, pm, "seg999")


def test_blocked_segments_round_trip_through_an_episode_file(tmp_path):
    ep = Episode("e", "straight_office", "easy", 0.0, 1.0, 0.0, "room6", 10.0, 0, False, 0, 0)
    closed = dataclasses.replace(ep, id="f", blocked=("seg4",))
    path = save_episodes([ep, closed], tmp_path / "e.json")
    plain, closed = load_episodes(path)
    assert plain.blocked == () and "blocked" not in plain.to_dict()
    assert closed.blocked == ("seg4",)
    text = path.read_text().replace('"seg4"', "4")
    path.write_text(text)
    with pytest.raises(EpisodeFileError, match="blocked"):
        load_episodes(path)
