"""Generated hospital, school and office floors (issue 36): valid over many seeds,
seeded, realistic widths and door pitch, every numbering scheme in use, names that
resolve to one room, and the development / held-out seed ranges of their families."""

from __future__ import annotations

import math
import re
from collections import Counter

import pytest

from pmnav_bt.errors import BuildingFileError, PmNavError
from pmnav_bt.experiments.options import building_names
from pmnav_bt.map.building import dump_building
from pmnav_bt.map.catalogue import (
    DEV_SEEDS,
    HELDOUT_SEEDS,
    family_members,
    is_generated_name,
    load_building,
)
from pmnav_bt.map.checks import door_warnings, shape_warnings
from pmnav_bt.map.floorplan import door_frames
from pmnav_bt.map.functional import BUILDING_KINDS, MIN_ROOM_M, generate_functional
from pmnav_bt.map.numbering import SCHEMES, room_code
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.programmes import PROGRAMMES
from pmnav_bt.planning.resolve import normalise
from pmnav_bt.sim.episodes import generate_episodes

SEEDS = range(25)
CASES = [(kind, seed) for kind in BUILDING_KINDS for seed in SEEDS]

# How each scheme's codes look (the code is the sign's first word).
SCHEME_PATTERNS = {
    "117": r"\d{3,}[AB]?",
    "1G": r"\d+[A-Z]{1,2}",
    "2.04": r"\d\.\d{2,}[AB]?",
    "L2-204": r"L\d-\d{3,}[AB]?",
    "B117": r"[A-Z]{1,2}\d{3,}",
}


@pytest.fixture(scope="module")
def buildings():
    return {case: generate_functional(*case) for case in CASES}


def test_every_floor_is_valid_with_doors_on_their_walls(buildings):
    # generate_functional validates (building_from_data raises on any problem); the
    # doors also sit on their corridor's wall, and no corridor is a stub or a kink.
    for (kind, seed), b in buildings.items():
        assert b.kind == kind and b.name == f"{kind}_{seed}"
        assert len(b.rooms) >= 10, (kind, seed)
        assert door_warnings(b) == [] and shape_warnings(b) == [], (kind, seed)
        kinds = Counter(lm.kind for lm in b.landmarks)
        assert kinds["reception_desk"] == 1 and kinds["elevator"] == 1 and kinds["stairs"] >= 1


def test_development_and_heldout_seeds_alike_give_valid_floors():
    for kind in BUILDING_KINDS:
        for seed in [*DEV_SEEDS[25:60], *HELDOUT_SEEDS[:60]]:
            assert len(generate_functional(kind, seed).rooms) >= 10  # it validated


def test_the_same_seed_gives_the_same_file_and_another_seed_another():
    for kind in BUILDING_KINDS:
        assert dump_building(generate_functional(kind, 7)) == dump_building(
            generate_functional(kind, 7)
        )
        a, b = generate_functional(kind, 7), generate_functional(kind, 8)
        assert [r.door for r in a.rooms] != [r.door for r in b.rooms]


def test_corridor_widths_are_the_types_and_doors_keep_room_for_their_signs(buildings):
    for (kind, _), b in buildings.items():
        lo, hi = PROGRAMMES[kind].corridor
        assert lo <= b.corridor_width <= hi
        widths = {b.edge_width(e) for e in b.edges}
        lobby = max(widths)
        assert PROGRAMMES[kind].lobby[0] <= lobby <= PROGRAMMES[kind].lobby[1]
        assert all(lo <= w <= hi for w in widths - {lobby})
        frames = door_frames(b)
        for i, f in enumerate(frames):
            for g in frames[i + 1 :]:
                same_wall = math.isclose(f.out[0], g.out[0], abs_tol=1e-6) and math.isclose(
                    f.out[1], g.out[1], abs_tol=1e-6
                )
                dx, dy = f.door[0] - g.door[0], f.door[1] - g.door[1]
                across = abs(dx * f.out[0] + dy * f.out[1])
                if same_wall and across < 0.05:
                    assert math.dist(f.door, g.door) >= MIN_ROOM_M - 0.01, (b.name, f.room, g.room)


def test_names_signs_and_aliases_each_resolve_to_one_room(buildings):
    for b in buildings.values():
        owner: dict[str, str] = {}
        for r in b.rooms:
            for key in {normalise(k) for k in (r.id, r.name, r.sign, *r.aliases) if k}:
                assert owner.setdefault(key, r.id) == r.id, (b.name, key, owner[key], r.id)


def test_every_numbering_scheme_appears_and_one_per_building(buildings):
    seen = Counter()
    for b in buildings.values():
        codes = [r.sign_text.split()[0] for r in b.rooms]
        fits = [s for s, p in SCHEME_PATTERNS.items() if all(re.fullmatch(p, c) for c in codes)]
        assert len(fits) == 1, (b.name, codes[:5])
        assert len(set(codes)) == len(codes), b.name
        seen[fits[0]] += 1
    assert set(seen) == set(SCHEMES)


def test_room_codes_spell_the_schemes():
    assert [room_code(s, 2, 4, "B") for s in SCHEMES] == ["204", "4B", "2.04", "L2-204", "B204"]
    with pytest.raises(ValueError, match="unknown numbering scheme"):
        room_code("roman", 2, 4, "B")


def test_type_rooms_are_named_as_the_type_names_them(buildings):
    names = {kind: set() for kind in BUILDING_KINDS}
    for (kind, _), b in buildings.items():
        names[kind] |= {re.sub(r" [\dA-Z.\-]+$", "", r.name) for r in b.rooms}
    assert {"Consulting Room", "Pharmacy", "Radiology"} <= names["hospital"]
    assert any(n.startswith("Ward ") and "Bay" in n for n in names["hospital"])
    assert {"Classroom", "Library", "Staff Room"} <= names["school"]
    assert {"Office", "Kitchen", "Print Room"} <= names["office"]
    assert any(n.startswith("Meeting Room ") for n in names["office"])


def test_every_tier_has_episodes_in_a_floor_of_each_type(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    for kind in BUILDING_KINDS:
        pm = parse_building(generate_functional(kind, 1))
        for tier in ("easy", "medium", "hard"):
            assert len(generate_episodes(pm, tier, 2, seed=0)) == 2, (kind, tier)


# -- the families ---------------------------------------------------------------------------


def test_the_seed_ranges_are_disjoint_and_the_heldout_spelling_names_heldout_seeds_only():
    assert not set(DEV_SEEDS) & set(HELDOUT_SEEDS)
    seeds = lambda names: {int(n.rpartition("_")[2]) for n in names}  # noqa: E731
    assert seeds(family_members("hospital:20")) == set(DEV_SEEDS[:20])
    held = family_members("functional_heldout:30")
    assert seeds(held) <= set(HELDOUT_SEEDS) and len(set(held)) == 30
    assert seeds(family_members("school_heldout:5")) == set(HELDOUT_SEEDS[:5])
    assert not seeds(family_members("functional:3000")) & set(HELDOUT_SEEDS)


def test_functional_cycles_the_types():
    assert family_members("functional:4") == ["hospital_0", "school_0", "office_0", "hospital_1"]
    assert family_members("functional_heldout:2") == ["hospital_1000", "school_1000"]
    assert building_names("fig2_hospital,office_heldout:1") == ["fig2_hospital", "office_1000"]


def test_members_load_by_name_and_seeds_outside_the_ranges_do_not(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    assert load_building("school_1003") == generate_functional("school", 1003)
    assert is_generated_name("office_1999") and not is_generated_name("office_2000")
    with pytest.raises(BuildingFileError, match="held-out") as err:
        load_building("office_2000")
    assert "\n" not in str(err.value)
    with pytest.raises(BuildingFileError, match="names 2 buildings; give one, such as hospital_0"):
        load_building("functional:2")


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("hospitl:3", "unknown building family 'hospitl'"),
        ("hospital:0", "N from 1 to 1000"),
        ("hospital:1001", "N from 1 to 1000"),
        ("functional:x", "N from 1 to 3000"),
        ("gen_small_heldout:2", "gen_small has no held-out seeds"),
        ("functional_heldout:", "N from 1 to 3000"),
    ],
)
def test_bad_family_specs_get_one_line_errors(spec, match):
    with pytest.raises(ValueError, match=match) as err:
        family_members(spec)
    assert "\n" not in str(err.value)
    with pytest.raises(PmNavError, match="--building"):
        building_names(spec)


def test_an_unknown_building_kind_is_refused():
    with pytest.raises(ValueError, match="unknown building kind 'prison'"):
        generate_functional("prison", 0)
