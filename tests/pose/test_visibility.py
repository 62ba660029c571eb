"""What the map says is readable where, and the landmark-density classes of Table 3."""

from __future__ import annotations

import numpy as np
import pytest

from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.generate import generate_sign_sparse
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.visibility import (
    LandmarkDensity,
    Visibility,
    density_class,
    entity_xy,
)
from pmnav_bt.seams import Entity


@pytest.fixture(scope="module")
def sparse():
    return parse_building(generate_sign_sparse(0))


def test_density_classes_follow_the_paper():
    assert density_class(0) == density_class(1) == LandmarkDensity.SCARCE
    assert density_class(2) == LandmarkDensity.MINIMAL
    assert density_class(3) == LandmarkDensity.REDUNDANT


def test_a_door_beside_the_robot_is_readable_and_one_far_away_is_not():
    pm = parse_building(load_building("straight_office"))
    vis = Visibility.of(pm)
    room = pm.building.rooms[0]
    door = np.array(room.door)
    here = pm.locate(*door).point(pm)
    assert Entity.room(room.id) in vis.readable_from(here)
    far = [r for r in pm.building.rooms if np.linalg.norm(np.array(r.door) - here) > 12.0]
    assert far and not any(Entity.room(r.id) in vis.readable_from(here) for r in far)


def test_walls_block_the_view_round_a_corner(sparse):
    vis = Visibility.of(sparse)
    # A lattice point and a sign within range whose sight line leaves the corridors.
    blocked = 0
    for p in vis.lattice_points[::7]:
        for e in vis.entities:
            d = np.linalg.norm(np.subtract(entity_xy(sparse, e), p.xy))
            if d < vis.read_range and e not in p.readable:
                blocked += 1
    assert blocked > 0


def test_the_sign_sparse_family_has_long_bare_stretches_and_near_identical_signs(
    sparse, tmp_path, monkeypatch
):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    vis = Visibility.of(sparse)
    bare = [p for p in vis.lattice_points if not p.readable]
    assert len(bare) * vis.lattice >= 40.0  # metres of corridor where nothing is readable
    signs = [r.sign for r in sparse.building.rooms]
    assert len(set(signs)) == len(signs)
    assert len({s[1:] for s in signs}) < len(signs)  # the same numbers in several wings
    assert generate_sign_sparse(0) == sparse.building  # seeded
    assert load_building("sign_sparse_0") == sparse.building  # by family name
    path = resolve_building_path("sign_sparse_0")  # written once to the cache folder
    assert path == tmp_path / "buildings" / "sign_sparse_0.yaml" and path.is_file()


def test_towards_signs_leads_from_every_bare_point(sparse):
    vis = Visibility.of(sparse)
    dist, nxt = vis.towards_signs
    for p in vis.lattice_points:
        if len(p.readable) >= 2:
            assert dist[p.index] == 0.0
        elif p.index in dist:
            assert dist[nxt[p.index]] < dist[p.index] + 1e-9


def test_the_trip_to_a_target_by_way_of_signs_is_never_shorter_than_the_route():
    """``exits_to``: each way's trip (find signs, then go on to the target) is at least
    the corridor route from the point, and for a point between a bare stretch and signs
    the way with the target behind the bare stretch can be the shorter trip."""
    pm = parse_building(generate_sign_sparse(2))
    vis = Visibility.of(pm, 3.5)
    target = entity_xy(pm, Entity.room("room14"))  # top of the east wing
    direct, trips = vis.distance_to(target), vis.exits_to(target)
    for p in vis.lattice_points[::7]:
        for t in trips[p.index].values():
            assert t >= direct[p.index] - 1e-6
    # Mid-way along the bare corridor from the west wing (signs 11 m west) to the
    # middle: the nearest signs are west, but the trip to room14 is shorter east.
    mid = vis.nearest_lattice((19.5, 30.0))
    east, west = trips[mid][0.0], trips[mid][3.14]
    near = dict(vis.exits[mid])
    assert near[3.14] < near[0.0]
    assert east < west - 10.0


def test_a_fire_door_is_not_a_sign_the_map_expects_to_be_read():
    from building_kit import with_landmark

    from pmnav_bt.map.building import Landmark

    b = load_building("straight_office")
    for kind, expected in (("sign", True), ("fire_door", False)):
        door = Landmark(id="fd1", kind=kind, name="FD-1", pos=(15.25, 1.1), sign="FD-1")
        vis = Visibility(parse_building(with_landmark(b, door)))
        assert (Entity.landmark("fd1") in vis.entities) is expected
