"""The site file: levels, lifts and stairs; every structural and meaning rule."""

from __future__ import annotations

import pytest
import yaml
from site_kit import changed, level_data, two_level_site

from pmnav_bt.errors import BuildingFileError, UnknownNameError
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.site import (
    ONE_LEVEL,
    builtin_sites,
    load_site,
    read_site_file,
    site_from_data,
)


def _problems(data) -> list[str]:
    with pytest.raises(BuildingFileError) as info:
        site_from_data(data, "s.yaml")
    assert "\n" not in info.value.summary() and "s.yaml" in info.value.summary()
    return [str(p) for p in info.value.problems]


def test_two_level_site_reads_with_its_lifts():
    site = site_from_data(two_level_site(), "s.yaml")
    assert site.level_names == ("L1", "L2")
    assert site.level("L2").building.name == "first"
    assert site.level("l2") is site.level("L2")  # a typed level name ignores case
    assert site.lift("liftB").lobbies == {"L1": "lB", "L2": "lB"}
    assert [lift.id for lift in site.lifts_at("L1")] == ["liftA", "liftB"]
    assert site.rank("L1") == 0 and site.rank("L2") == 1


def test_levels_rank_by_elevation_not_file_order():
    data = two_level_site()
    data["levels"][0]["elevation"] = 8.0
    site = site_from_data(data, "s.yaml")
    assert site.rank("L2") == 0 and site.rank("L1") == 1


def test_unknown_level_and_lift_name_the_known_ones():
    site = site_from_data(two_level_site(), "s.yaml")
    with pytest.raises(UnknownNameError, match="L1, L2"):
        site.level("L7")
    with pytest.raises(UnknownNameError, match="liftA, liftB"):
        site.lift("liftC")


def test_level_building_by_file_and_by_builtin_name(tmp_path):
    data = two_level_site()
    (tmp_path / "floors").mkdir()
    (tmp_path / "floors" / "l2.yaml").write_text(yaml.safe_dump(data["levels"][1]["building"]))
    data["levels"][1]["building"] = "floors/l2.yaml"
    data["levels"].append({"name": "L3", "elevation": 8.0, "building": "fig2_hospital"})
    data["lifts"][0]["lobbies"]["L3"] = "elevator1"
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(data))
    site = read_site_file(tmp_path / "site.yaml")
    assert site.level("L2").path == tmp_path / "floors" / "l2.yaml"
    assert site.level("L3").building == load_building("fig2_hospital")
    assert site.level("L1").path is None  # inline
    assert site.path == tmp_path / "site.yaml"


def test_load_site_takes_a_building_as_one_level():
    site = load_site("fig2_hospital")
    assert site.level_names == (ONE_LEVEL,) and not site.lifts
    assert site.levels[0].building == load_building("fig2_hospital")


def test_load_site_takes_a_site_file_and_a_builtin_site(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(two_level_site()))
    assert load_site(tmp_path / "s.yaml").level_names == ("L1", "L2")
    assert "hospital_2l" in builtin_sites()
    assert len(load_site("hospital_2l").levels) == 2


def test_unknown_name_lists_buildings_and_sites():
    with pytest.raises(BuildingFileError, match="built-in sites: .*hospital_2l"):
        load_site("no_such_place")


def test_read_site_file_refuses_a_building_file():
    from pmnav_bt.map.catalogue import resolve_building_path

    with pytest.raises(BuildingFileError, match="site_version: required key is missing"):
        read_site_file(resolve_building_path("fig2_hospital"))


# -- structure ----------------------------------------------------------------------------


def test_structure_errors_name_their_fields():
    data = two_level_site()
    data["levels"][0]["colour"] = "red"
    data["levels"][1]["building"] = 3
    data["lifts"][0]["lobbies"] = {"L1": "lA", "a/b": "lA"}
    found = _problems(data)
    assert any(p.startswith("levels[0].colour: unknown key") for p in found)
    assert any(p.startswith("levels[1].building: give the level's building file") for p in found)
    assert any(p.startswith("lifts[0].lobbies.a/b") and "level name" in p for p in found)


def test_site_version_is_checked():
    assert _problems(changed(two_level_site(), site_version=2)) == [
        "site_version: this version of pmnav reads site_version 1, not 2"
    ]
    assert any("site_version" in p for p in _problems(changed(two_level_site(), site_version="1")))


def test_no_levels():
    assert _problems(changed(two_level_site(), levels=[], lifts=[])) == [
        "levels: a site needs at least 1 level"
    ]


def test_a_level_building_problem_has_the_level_path():
    data = two_level_site()
    data["levels"][1]["building"]["rooms"][0]["door"] = [10.0, 30.0]
    (found,) = _problems(data)
    assert found.startswith("levels[1].building.rooms[0].door: 'room201' is")


def test_a_level_file_problem_names_the_file(tmp_path):
    data = two_level_site()
    data["levels"][1]["building"] = "missing.yaml"
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    with pytest.raises(BuildingFileError) as info:
        read_site_file(tmp_path / "s.yaml")
    (p,) = info.value.problems
    assert p.field == "levels[1].building" and "missing.yaml" in p.message


# -- meaning -------------------------------------------------------------------------------


def test_duplicate_level_names_ignore_case():
    data = two_level_site()
    data["levels"][1]["name"] = "l1"
    found = _problems(data)
    assert found[0].startswith("levels[1].name: duplicate level 'l1' (also at levels[0]")


def test_lobby_on_an_unknown_level():
    data = two_level_site()
    data["lifts"][0]["lobbies"]["L9"] = "lA"
    assert _problems(data) == ["lifts[0].lobbies.L9: unknown level 'L9' (levels: L1, L2)"]


def test_lift_with_a_lobby_on_one_level_only():
    data = two_level_site()
    del data["lifts"][1]["lobbies"]["L2"]
    (found,) = _problems(data)
    assert found.startswith("lifts[1].lobbies: lift 'liftB' has a lobby on 1 level(s) (L1)")


def test_lobby_that_is_not_a_landmark_of_its_level():
    data = two_level_site()
    data["lifts"][0]["lobbies"]["L2"] = "lZ"
    (found,) = _problems(data)
    assert found == (
        "lifts[0].lobbies.L2: 'lZ' is not a landmark of level L2 (its lift landmarks: lA, lB)"
    )


def test_lobby_that_is_not_a_lift():
    data = two_level_site()
    data["levels"][1]["building"]["landmarks"][0]["kind"] = "reception_desk"
    (found,) = _problems(data)
    assert found.startswith("lifts[0].lobbies.L2: 'lA' on level L2 is a reception_desk, not a lift")


def test_stairs_lobby_must_be_stairs():
    data = two_level_site()
    data["stairs"] = [{"id": "st1", "lobbies": {"L1": "lA", "L2": "lA"}}]
    found = _problems(data)
    assert found[0].startswith("stairs[0].lobbies.L1: 'lA' on level L1 is a elevator, not a stairs")


def test_lift_and_stairs_ids_are_one_namespace():
    data = two_level_site()
    for lv in data["levels"]:
        lv["building"]["landmarks"].append({"id": "s", "kind": "stairs", "pos": [20.0, -1.2]})
    data["stairs"] = [{"id": "liftA", "lobbies": {"L1": "s", "L2": "s"}}]
    assert _problems(data) == ["stairs[0].id: duplicate id 'liftA' (also at lifts[0])"]


def test_a_level_no_lift_reaches():
    data = two_level_site()
    data["levels"].append(
        {"name": "L3", "elevation": 8.0, "building": level_data("x", {"room301": 9.0}, {})}
    )
    assert _problems(data) == [
        "levels[2]: level 'L3' has no way from its corridors to any lift: no lift has a lobby "
        "on it; give a lift's lobby on this level"
    ]


def test_a_level_reached_by_stairs_only():
    data = two_level_site()
    l3 = level_data("x", {"room301": 9.0}, {})
    l3["landmarks"] = [{"id": "s", "kind": "stairs", "pos": [20.0, -1.2]}]
    data["levels"][0]["building"]["landmarks"].append(
        {"id": "s", "kind": "stairs", "pos": [20.0, -1.2]}
    )
    data["levels"].append({"name": "L3", "elevation": 8.0, "building": l3})
    data["stairs"] = [{"id": "st", "lobbies": {"L1": "s", "L3": "s"}}]
    (found,) = _problems(data)
    assert "'L3' has no way" in found and "stairs st are never driven" in found


def test_levels_in_separate_lift_parts():
    data = two_level_site()
    for name in ("L3", "L4"):
        data["levels"].append(
            {"name": name, "elevation": 9.0, "building": level_data(name, {}, {"lC": 5.0})}
        )
    data["lifts"].append({"id": "liftC", "lobbies": {"L3": "lC", "L4": "lC"}})
    assert _problems(data) == [
        "lifts: the lifts join the levels in 2 separate parts: {L1, L2}; {L3, L4}"
    ]


def test_one_level_site_needs_no_lift():
    data = two_level_site()
    data["levels"] = data["levels"][:1]
    data["lifts"] = []
    assert site_from_data(data, "s.yaml").level_names == ("L1",)
