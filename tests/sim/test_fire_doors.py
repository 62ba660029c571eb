"""Fire doors in the simulator: shut with the probability the world asks for, replayed
from the seed; shut, the leaves close the corridor from wall to wall; open, they lie
against the walls and leave the corridor free; either way nothing of them is a sign
(no plate on a wall, no landmark label a grounder could read)."""

from __future__ import annotations

import numpy as np
import pytest
from building_kit import with_landmark
from shapely.geometry import LineString, Point
from shapely.ops import unary_union

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.building import Landmark
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import OBSTACLE_LABEL, landmark_label
from pmnav_bt.sim.robot import COLLISION_HEIGHT
from pmnav_bt.sim.scene.fire_doors import fire_doors_closed
from pmnav_bt.sim.world import SimWorld

pytestmark = pytest.mark.world

ROBOT_DIAMETER_M = 0.34  # a Create 3


def test_fire_doors_are_shut_with_the_probability_asked_for_from_the_seed():
    ids = [f"fd{k}" for k in range(400)]

    def shut(p: float, seed: int) -> dict:
        return fire_doors_closed(ids, p, np.random.default_rng(seed))

    assert not any(shut(0.0, 1).values()) and all(shut(1.0, 1).values())
    assert shut(0.3, 1) == shut(0.3, 1) != shut(0.3, 2)
    assert 0.2 < np.mean(list(shut(0.3, 1).values())) < 0.4


@pytest.fixture(scope="module")
def office():
    door = Landmark(id="fd1", kind="fire_door", name="FD-1", pos=(15.25, 1.1))  # at a wall
    return with_landmark(load_building("straight_office"), door)


@pytest.mark.parametrize("p", [0.0, 1.0])
def test_a_shut_fire_door_closes_its_corridor_and_an_open_one_leaves_it_free(office, p):
    with SimWorld(office, scene=WorldConfig(fire_doors_closed=p)) as w:
        fd = w.fire_doors["fd1"]
        assert fd.closed is (p == 1.0)
        (x0, y0), (x1, y1) = fd.line
        # square to the corridor, across it from wall to wall (2.2 m), at the door's x
        assert x0 == pytest.approx(15.25) and x1 == pytest.approx(15.25)
        assert abs(y1 - y0) == pytest.approx(office.corridor_width)
        leaves = unary_union(w.obstacle_footprints(COLLISION_HEIGHT))
        line = LineString(fd.line)
        widest_gap = line.length - line.intersection(leaves).length
        if fd.closed:
            assert widest_gap < ROBOT_DIAMETER_M / 4
        else:
            assert line.length - widest_gap < 2 * 0.06  # two leaves' thickness, at the walls
        assert "fd1" not in w.landmarks and "fd1" not in w.landmark_signs  # not on a wall
        assert {w.label_of(b) for b in fd.bodies} == {OBSTACLE_LABEL}  # no sign to read
        assert not w.bodies_with_label(landmark_label("fd1"))
        # down the corridor beside its middle (the leaves meet there), at bumper height
        hit = w.ray((12.0, 0.3, 0.2), (19.0, 0.3, 0.2))
        if fd.closed:
            assert hit.body in fd.bodies and hit.distance == pytest.approx(3.2, 0.01)
        else:
            assert hit is None


def test_clutter_keeps_clear_of_where_a_fire_door_swings(office):
    cfg = WorldConfig(preset="realistic", people_per_100m=0.0, clutter_per_10m=5.0)
    with SimWorld(office, scene=cfg, seed=3) as w:
        line = LineString(w.fire_doors["fd1"].line)
        assert w.clutter  # a corridor full of it
        assert all(line.distance(Point(c.centre)) > line.length / 2.0 for c in w.clutter)
