"""Generated building families by name: FAMILY:N specs, the small family of the scale test,
and episodes that find their generated building again on another machine (a Ray node)."""

from __future__ import annotations

import dataclasses

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.experiments.options import building_names
from pmnav_bt.map.catalogue import family_members, generated_family, load_building
from pmnav_bt.map.wall_items import wall_item_warnings
from pmnav_bt.sim.episodes import episode_building_file, generate_episodes


def test_family_specs_name_the_first_members():
    assert family_members("gen_small:3") == ["gen_small_0", "gen_small_1", "gen_small_2"]
    assert family_members("straight_office") is None
    with pytest.raises(ValueError, match="unknown building family"):
        family_members("nope:3")
    with pytest.raises(ValueError, match="from 1 to"):
        family_members("gen_small:0")


def test_the_building_option_mixes_families_and_names():
    assert building_names("straight_office,sign_sparse:2") == [
        "straight_office",
        "sign_sparse_0",
        "sign_sparse_1",
    ]
    with pytest.raises(PmNavError, match="--building"):
        building_names("gen_small:x")


def test_small_family_members_are_seeded_and_pose_easy_episodes(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    b = generated_family("gen_small_4")
    assert b == generated_family("gen_small_4") and len(b.rooms) == 10
    assert generated_family("gen_small_5") != b
    eps = generate_episodes("gen_small_4", "easy", 3, seed=0)
    assert len(eps) == 3 and all(e.building == "gen_small_4" for e in eps)


def test_an_episode_finds_its_generated_building_where_its_file_is_missing(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path / "driver"))
    ep = generate_episodes("gen_small_1", "easy", 1, seed=0)[0]
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path / "node"))  # another machine's cache
    moved = dataclasses.replace(ep, building_path=str(tmp_path / "gone" / "gen_small_1.yaml"))
    path = episode_building_file(moved)
    assert path.is_file() and str(path).startswith(str(tmp_path / "node"))


@pytest.mark.parametrize("family", ["gen_small", "sign_sparse"])
def test_no_generated_lift_or_stairs_hangs_through_a_door(family):
    """Lifts and stairs go on a wall of a corridor that leaves their junction, slid clear
    of its doors (they once sat in a turn's corner, past its corridors, and the simulator
    hung them over the nearest door)."""
    for name in family_members(f"{family}:10"):
        b = load_building(name)
        clashes = [p.message for p in wall_item_warnings(b) if p.field.startswith("landmarks")]
        assert not clashes, (name, clashes)
