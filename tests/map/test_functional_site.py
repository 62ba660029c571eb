"""Generated sites of several levels (issue 40): every seed validates, the levels stack
on one structure (corridors over each other, the lift and stairs at one place), every
level reaches the lift and every room on another level is a ride away, room codes name
their floor, and the sites are named, written and found like the one-floor families."""

from __future__ import annotations

import math
import random

import pytest

from pmnav_bt.errors import BuildingFileError
from pmnav_bt.experiments.options import building_names
from pmnav_bt.map.catalogue import (
    DEV_SEEDS,
    HELDOUT_SEEDS,
    family_members,
    generated_site_path,
    is_generated_site_name,
    load_building,
)
from pmnav_bt.map.functional import BUILDING_KINDS
from pmnav_bt.map.functional_site import LEVELS, LIFT_ID, generate_functional_site
from pmnav_bt.map.landmark_kinds import ELEVATOR, ELEVATOR_PANEL_M, landmark_shape
from pmnav_bt.map.lift_doorway import doorway
from pmnav_bt.map.site import Site, load_site, site_from_data
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.planning.resolve import resolve_start
from pmnav_bt.planning.site_plan import SitePlanner
from pmnav_bt.sim.site_episodes import generate_site_episodes, site_ref

SEEDS = [*range(8), *range(1000, 1003)]
CASES = [(kind, seed) for kind in BUILDING_KINDS for seed in SEEDS]


@pytest.fixture(scope="module")
def sites() -> dict[tuple[str, int], Site]:
    # site_from_data validates the whole site (each level's building, the lift lobbies,
    # every level reaching a lift) and raises on any problem
    return {case: site_from_data(generate_functional_site(*case).site_data()) for case in CASES}


def test_every_site_validates_with_two_to_four_levels(sites):
    counts = set()
    for (kind, seed), site in sites.items():
        assert site.name == f"{kind}_site_{seed}"
        assert LEVELS[0] <= len(site.levels) <= LEVELS[1], (kind, seed)
        assert all(lv.building.kind == kind for lv in site.levels)
        assert [site.rank(lv.name) for lv in site.levels] == list(range(len(site.levels)))
        counts.add(len(site.levels))
    assert counts == set(range(LEVELS[0], LEVELS[1] + 1))


def test_the_levels_stack_on_one_structure(sites):
    for case, site in sites.items():
        ground = site.levels[0].building
        for lv in site.levels[1:]:
            b = lv.building
            assert [(w.id, w.pos) for w in b.waypoints] == [(w.id, w.pos) for w in ground.waypoints]
            assert b.edges == ground.edges, case
        for link in (*site.lifts, *site.stairs):  # one shaft, one stairwell: one place
            places = {tuple(site.level(lv).building.landmark(lm).pos)
                      for lv, lm in link.lobbies.items()}  # fmt: skip
            assert len(places) == 1, (case, link.id)


def test_every_lift_serves_every_level_and_only_the_ground_floor_has_reception(sites):
    for case, site in sites.items():
        assert site.lifts, case
        for lift in site.lifts:
            assert set(lift.lobbies) == set(site.level_names), case
            for level, lobby in lift.lobbies.items():
                kind = site.level(level).building.landmark(lobby).kind
                assert landmark_shape(kind) is ELEVATOR, case
        receptions = [
            lv.name for lv in site.levels
            if any(lm.kind == "reception_desk" for lm in lv.building.landmarks)
        ]  # fmt: skip
        assert receptions == [site.levels[0].name], case


def test_the_lift_stands_on_the_wall_its_doorway_is_cut_through(sites):
    # the map puts a lift's doorway on the wall of the corridor nearest its point, and the
    # simulator cuts it through the wall nearest its point: the point must be on that wall
    # (the doors half a call panel beside it), not out in a lobby in front of a wall
    for case, site in sites.items():
        sm = parse_site(site)
        for lv in site.levels:
            lift = lv.building.landmark(LIFT_ID)
            gap = math.dist(lift.pos, doorway(sm.maps[lv.name], LIFT_ID).centre)
            assert gap == pytest.approx(ELEVATOR_PANEL_M / 2.0, abs=0.01), (case, lv.name)


def test_every_level_reaches_a_room_on_every_other_level_by_one_ride(sites):
    # from each level's start (the ground floor's entrance), to a room drawn on each other
    # level: the plan walks to the lift, rides it once, and walks on to the room
    planner = SitePlanner()
    for case, site in sites.items():
        sm = parse_site(site)
        rng = random.Random(f"{case}")
        for a in site.level_names:
            start = resolve_start(sm.maps[a], "start")
            for b in site.level_names:
                if a == b:
                    continue
                room = rng.choice(site.level(b).building.rooms).id
                plan = planner.plan(sm, a, start, f"{b}/{room}")
                assert [(r.from_level, r.to_level) for r in plan.rides] == [(a, b)], case
                assert [leg.level for leg in plan.legs] == [a, b]


def test_room_codes_name_their_floor_and_no_code_is_on_two_levels(sites):
    for case, site in sites.items():
        seen: dict[str, str] = {}
        for k, lv in enumerate(site.levels, start=1):
            for room in lv.building.rooms:
                code = room.sign.split()[0]
                assert str(k) in code, (case, lv.name, code)
                assert seen.setdefault(code, lv.name) == lv.name, (case, code)


def test_the_levels_differ_in_their_rooms():
    site = site_from_data(generate_functional_site("hospital", 5).site_data())
    names = [tuple(r.name for r in lv.building.rooms) for lv in site.levels]
    assert len(set(names)) == len(names)


def test_the_same_seed_gives_the_same_site_and_another_seed_another():
    a, b = generate_functional_site("office", 7), generate_functional_site("office", 7)
    assert a == b
    assert generate_functional_site("office", 8).levels != a.levels


def test_an_unknown_kind_is_refused():
    with pytest.raises(ValueError, match="unknown building kind 'prison'"):
        generate_functional_site("prison", 0)


# -- names -----------------------------------------------------------------------------------


def test_site_families_name_development_and_heldout_members():
    assert family_members("functional_site:4") == [
        "hospital_site_0", "school_site_0", "office_site_0", "hospital_site_1",
    ]  # fmt: skip
    assert family_members("functional_site_heldout:2") == ["hospital_site_1000", "school_site_1000"]
    assert family_members("office_site_heldout:2") == ["office_site_1000", "office_site_1001"]
    assert building_names("hospital_2l,school_site:1") == ["hospital_2l", "school_site_0"]
    assert is_generated_site_name(f"office_site_{HELDOUT_SEEDS[-1]}")
    assert not is_generated_site_name(f"office_site_{HELDOUT_SEEDS[-1] + 1}")
    assert not is_generated_site_name("office_3")  # a floor, not a site
    with pytest.raises(ValueError, match="N from 1 to 3000"):
        family_members("functional_site:0")


def test_a_site_loads_by_name_and_its_episodes_name_it(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    name = f"school_site_{DEV_SEEDS[3]}"
    site = load_site(name)
    assert site.path == generated_site_path(name) and site.path.is_relative_to(tmp_path)
    fresh = site_from_data(generate_functional_site("school", 3).site_data())
    assert [lv.building for lv in site.levels] == [lv.building for lv in fresh.levels]
    assert (site.lifts, site.stairs) == (fresh.lifts, fresh.stairs)
    assert site_ref(site) == name
    eps = generate_site_episodes(name, 2, seed=1)
    assert [ep.site for ep in eps] == [name, name]
    assert all(ep.start_level != ep.goal_level and ep.rides == 1 for ep in eps)


def test_a_site_seed_outside_the_ranges_is_refused_in_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    with pytest.raises(BuildingFileError, match="held-out") as err:
        load_site("hospital_site_2000")
    assert "\n" not in str(err.value)
    with pytest.raises(BuildingFileError, match="names 2 buildings; give one"):
        load_site("functional_site:2")
    with pytest.raises(BuildingFileError, match="a generated site of several levels"):
        load_building("hospital_site_3")
