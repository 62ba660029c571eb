"""The building file's signage section: a good one loads and round-trips, each bad field
gets one clear problem, room numbers in the schemes buildings use are told apart."""

from __future__ import annotations

import copy

import pytest
import yaml

from pmnav_bt.errors import BuildingFileError
from pmnav_bt.map.building import building_from_data, dump_building
from pmnav_bt.map.signage import split_number
from pmnav_bt.sim.scene.signage import CLEAN_STYLE

GOOD = {  # a corridor with two rooms: room2 is the toilet
    "schema_version": 1,
    "name": "tiny",
    "waypoints": [
        {"id": "start", "kind": "start", "pos": [0, 0]},
        {"id": "end1", "kind": "end", "pos": [10, 0]},
    ],
    "edges": [["start", "end1"]],
    "rooms": [
        {"id": "room1", "name": "Office", "door": [5, 1.2], "sign": "101 Office"},
        {"id": "room2", "name": "WC", "door": [5, -1.2]},
    ],
}

SECTION = {
    "style": {
        "plate_width": 0.3,
        "cap_height": 0.04,
        "font": "dejavu_sans_bold",
        "text_rgb": [255, 255, 255],
        "plate_rgb": [20, 60, 120],
        "mounting": "beside_left",
        "layout": "number_and_name",
        "height": 1.5,
    },
    "rooms": {"room1": {"mounting": "flag"}, "room2": {"pictogram": "toilet"}},
    "directional": [{"at": [9.0, 0.5], "text": "Offices ->"}],
}


def with_signage(section) -> dict:
    data = copy.deepcopy(GOOD)
    data["signage"] = section
    return data


def problems(section) -> list[str]:
    with pytest.raises(BuildingFileError) as info:
        building_from_data(with_signage(section), "t.yaml")
    return [str(p) for p in info.value.problems]


def test_a_full_section_loads_and_round_trips():
    b = building_from_data(with_signage(SECTION))
    assert b.signage.style.font == "dejavu_sans_bold"
    assert b.signage.style.plate_rgb == (20, 60, 120)
    assert b.signage.rooms["room2"].pictogram == "toilet"
    room1 = CLEAN_STYLE.merged(b.signage.style).merged(b.signage.rooms["room1"])
    assert (room1.mounting, room1.plate_width) == ("flag", 0.3)  # the override, then the style
    assert building_from_data(yaml.safe_load(dump_building(b))) == b


def test_every_field_is_optional():
    b = building_from_data(with_signage({}))
    assert CLEAN_STYLE.merged(b.signage.style) == CLEAN_STYLE
    assert building_from_data(GOOD).signage is None


@pytest.mark.parametrize(
    "field, value, expect",
    [
        ("plate_width", 0.05, "signage.style.plate_width: Input should be greater than or equal"),
        ("plate_width", 1.2, "signage.style.plate_width: Input should be less than or equal"),
        ("cap_height", 0.2, "signage.style.cap_height: Input should be less than or equal"),
        ("height", 4.0, "signage.style.height: Input should be less than or equal"),
        ("font", "comic_sans", "signage.style.font: unknown font; choose one of hershey,"),
        ("mounting", "ceiling", "signage.style.mounting: Input should be 'beside'"),
        ("layout", "name_first", "signage.style.layout: Input should be 'number_and_name'"),
        ("text_rgb", [255, 255], "signage.style.text_rgb: a colour is 3 integers 0-255"),
        ("plate_rgb", [0, 0, 256], "signage.style.plate_rgb: a colour is 3 integers 0-255"),
        ("plate_rgb", [0.5, 0, 0], "signage.style.plate_rgb: a colour is 3 integers 0-255"),
        ("plate_rgb", "navy", "signage.style.plate_rgb: a colour is 3 integers 0-255"),
        ("colour", [0, 0, 0], "signage.style.colour: unknown key"),
    ],
)
def test_one_clear_problem_per_bad_style_field(field, value, expect):
    got = problems({"style": {field: value}})
    assert len(got) == 1 and got[0].startswith(expect), got


def test_overrides_name_known_rooms_and_take_only_known_pictograms():
    got = problems({"rooms": {"room9": {"mounting": "flag"}, "room1": {}}})
    assert got == ["signage.rooms.room9: unknown room 'room9' (not in rooms)"]
    got = problems({"rooms": {"room1": {"pictogram": "cat"}}})
    assert len(got) == 1 and got[0].startswith("signage.rooms.room1.pictogram: Input should be")


def test_directional_signs_stand_by_a_corridor_and_say_something():
    got = problems({"directional": [{"at": [50.0, 50.0], "text": "Radiology ->"}]})
    assert len(got) == 1
    assert got[0].startswith("signage.directional[0].at: sign 'Radiology ->' is ")
    got = problems({"directional": [{"at": [5.0, 0.0], "text": ""}]})
    assert got[0].startswith("signage.directional[0].text: String should have at least 1")


def test_every_problem_of_the_section_is_collected():
    got = problems({"style": {"font": "x", "mounting": "y"}, "directional": [{"at": [1, 2]}]})
    assert [g.split(":")[0] for g in got] == [
        "signage.style.font",
        "signage.style.mounting",
        "signage.directional[0].text",
    ]


@pytest.mark.parametrize(
    "text, parts",
    [
        ("117 Laboratory", ("117", "Laboratory")),
        ("1G Pharmacy", ("1G", "Pharmacy")),
        ("2.04 Radiology", ("2.04", "Radiology")),
        ("L2-204 Radiology", ("L2-204", "Radiology")),
        ("B117 Stores", ("B117", "Stores")),
        ("105", ("105", "")),
        ("Radiology", ("", "Radiology")),
        ("X-ray Suite", ("", "X-ray Suite")),
    ],
)
def test_room_numbers_in_every_scheme(text, parts):
    assert split_number(text) == parts
