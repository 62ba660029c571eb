"""The six built-in sim buildings: valid, big enough, realistic, and structurally distinct."""

from __future__ import annotations

import itertools
import math

import networkx as nx
import numpy as np
import pytest

from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.building import WaypointKind
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.priori_map import parse_building

# name -> (turn waypoints, branch waypoints, corridor loop?) as each file claims.
STRUCTURE = {
    "straight_office": (0, 0, False),
    "l_hospital": (1, 0, False),
    "t_school": (2, 2, False),
    "u_office": (2, 1, False),
    "loop_hospital": (4, 1, True),
    "ring_school": (4, 4, True),
}
LANDMARK_KINDS = {"elevator", "stairs", "reception_desk"}


def _structure(b) -> tuple[int, int, bool]:
    kinds = [w.kind for w in b.waypoints]
    has_cycle = bool(nx.cycle_basis(b.corridor_graph()))
    return kinds.count(WaypointKind.TURN), kinds.count(WaypointKind.BRANCH), has_cycle


def _edges(b):
    wps = {w.id: np.array(w.pos, float) for w in b.waypoints}
    a = np.array([wps[e.a] for e in b.edges])
    z = np.array([wps[e.b] for e in b.edges])
    half = np.array([b.edge_width(e) / 2 for e in b.edges])
    return a, z, half


@pytest.fixture(scope="module", params=sorted(STRUCTURE))
def building(request):
    return load_building(request.param)


def test_all_six_are_built_in():
    assert set(STRUCTURE) <= set(builtin_buildings())


def test_loads_parses_and_is_big_enough(building):
    pm = parse_building(building)
    assert len(building.rooms) >= 20
    assert set(pm.places) >= {r.id for r in building.rooms}
    assert building.kind in ("hospital", "school", "office")
    assert nx.is_connected(building.corridor_graph())


def test_sizes_are_typical(building):
    a, z, half = _edges(building)
    lengths = np.linalg.norm(z - a, axis=1)
    assert np.all((2 * half >= 2.0) & (2 * half <= 3.0))
    assert lengths.max() <= 60.0
    pts = np.array([w.pos for w in building.waypoints])
    extent = (pts.max(axis=0) - pts.min(axis=0)).max()
    assert 20.0 <= extent <= 80.0


def test_doors_sit_in_the_wall_of_a_straight_corridor(building):
    a, z, half = _edges(building)
    doors = np.array([r.door for r in building.rooms])
    j, _, dist = project_points_to_segments(doors, a, z)
    # Exactly at half the corridor width from the centre line: in the wall.
    np.testing.assert_allclose(dist, half[j], atol=1e-6)
    # At least 1 m of straight wall beyond the crossing corridor's wall at every junction,
    # and 1 m from the end walls.
    g = building.corridor_graph()
    for w in building.waypoints:
        need = (building.corridor_width / 2 + 1.0) if g.degree(w.id) >= 2 else 1.0
        foot_dist = np.sqrt(
            np.maximum(np.linalg.norm(doors - np.array(w.pos), axis=1) ** 2 - dist**2, 0.0)
        )
        assert foot_dist.min() >= need - 1e-6, (w.id, foot_dist.argmin())


def test_doors_and_landmarks_are_spaced(building):
    pts = [(r.id, r.door) for r in building.rooms]
    for (i, p), (k, q) in itertools.combinations(pts, 2):
        assert math.dist(p, q) >= 1.4, (i, k)
    for lm in building.landmarks:
        for rid, p in pts:
            assert math.dist(lm.pos, p) >= 1.0, (lm.id, rid)


def test_names_signs_and_landmarks_are_realistic(building):
    numbered = [r for r in building.rooms if r.sign.isdigit()]
    named = [r for r in building.rooms if not r.sign.isdigit()]
    assert len(numbered) > len(named) >= 5
    assert all(r.sign.split()[0].isdigit() for r in named)
    assert any(r.aliases for r in building.rooms)
    assert len({r.sign for r in building.rooms}) == len(building.rooms)
    kinds = {lm.kind for lm in building.landmarks}
    assert kinds >= LANDMARK_KINDS
    assert any("service centre" in lm.name.lower() for lm in building.landmarks)


def test_structure_is_as_claimed_and_distinct():
    seen = {name: _structure(load_building(name)) for name in STRUCTURE}
    assert seen == STRUCTURE
    assert len(set(seen.values())) == len(seen)
