"""Building files: loading, one message per class of bad file, and round-trips."""

from __future__ import annotations

import copy
import math

import cv2
import numpy as np
import pytest
import yaml

from pmnav_bt.errors import BuildingFileError
from pmnav_bt.map.building import Building, building_from_data, dump_building, save_building
from pmnav_bt.map.catalogue import builtin_buildings, load_building

GOOD = {
    "schema_version": 1,
    "name": "tiny",
    "corridor_width": 2.0,
    "waypoints": [
        {"id": "start", "kind": "start", "pos": [0, 0]},
        {"id": "turn1", "kind": "turn", "pos": [10, 0]},
        {"id": "end1", "kind": "end", "pos": [10, 10]},
    ],
    "edges": [["start", "turn1"], {"from": "turn1", "to": "end1", "width": 2.5}],
    "rooms": [
        {"id": "room1", "name": "Office", "aliases": ["Boss"], "door": [5, 1.0], "sign": "101"},
        {"id": "room2", "door": [11.25, 5]},
    ],
    "landmarks": [{"id": "lift", "kind": "elevator", "pos": [5, -1.0]}],
}


def bad(mutate) -> list[str]:
    """Apply ``mutate`` to a copy of GOOD and return the problems as 'field: message' lines."""
    data = copy.deepcopy(GOOD)
    mutate(data)
    with pytest.raises(BuildingFileError) as info:
        building_from_data(data, "t.yaml")
    return [str(p) for p in info.value.problems]


def test_good_building_loads_with_defaults():
    b = building_from_data(GOOD)
    assert b.room("room1").display_name == "Office"
    assert b.room("room2").display_name == "room2"
    assert b.room("room2").sign_text == "room2"
    assert b.edge_width(b.edges[0]) == 2.0 and b.edge_width(b.edges[1]) == 2.5
    assert b.corridor_graph().edges["turn1", "end1"]["length"] == pytest.approx(10.0)


@pytest.mark.parametrize(
    "mutate, field, words",
    [
        (lambda d: d["rooms"].append(dict(d["rooms"][0])), "rooms[2].id", "duplicate id 'room1'"),
        (
            lambda d: d["landmarks"].append({"id": "start", "kind": "x", "pos": [1, 0]}),
            "landmarks[1].id",
            "duplicate id 'start'",
        ),
        (lambda d: d["edges"].append(["end1", "nowhere"]), "edges[2].to", "unknown waypoint"),
        (lambda d: d["edges"].append(["turn1", "turn1"]), "edges[2]", "to itself"),
        (lambda d: d["edges"].append(["turn1", "start"]), "edges[2]", "duplicate edge"),
        (lambda d: d["rooms"][0].update(door=[5, 9]), "rooms[0].door", "from the nearest corridor"),
        (lambda d: d["landmarks"][0].update(pos=[30, 30]), "landmarks[0].pos", "nearest corridor"),
        (
            lambda d: (
                d["waypoints"].extend(
                    [
                        {"id": "a", "kind": "start", "pos": [50, 50]},
                        {"id": "b", "kind": "end", "pos": [60, 50]},
                    ]
                ),
                d["edges"].append(["a", "b"]),
            ),
            "edges",
            "2 disconnected parts",
        ),
        (lambda d: d["waypoints"][1].update(kind="branch"), "waypoints[1].kind", "use kind 'turn'"),
        (lambda d: d["rooms"][0].update(door=[5, float("nan")]), "rooms[0].door[1]", "finite"),
        (lambda d: d["rooms"][0].update(door=[5, "north"]), "rooms[0].door[1]", "number"),
        (lambda d: d.update(corridor_width=-1), "corridor_width", "greater than 0"),
        (lambda d: d["rooms"][0].update(colour="red"), "rooms[0].colour", "unknown key"),
        (lambda d: d["rooms"][0].update(amenity="kitchen"), "rooms[0].amenity", "'toilet'"),
        (lambda d: d.update(floors=2), "floors", "unknown key"),
        (lambda d: d.pop("name"), "name", "missing"),
        (lambda d: d.update(schema_version=7), "schema_version", "reads schema_version 1"),
        (lambda d: d["waypoints"][0].update(kind="door"), "waypoints[0].kind", "start"),
        (lambda d: d["edges"].append(["start"]), "edges[2]", "[from, to]"),
        (
            lambda d: d["edges"].append({"from": "start", "to": "end1", "width": 0}),
            "edges[2].width",
            "greater than 0",
        ),
        (lambda d: d.update(floor_plan={"image": "plan.png"}), "floor_plan", "metres_per_pixel"),
        (
            lambda d: d.update(
                floor_plan={"image": "a.png", "metres_per_pixel": 0.1, "ros_map": "m.yaml"}
            ),
            "floor_plan",
            "either",
        ),
    ],
)
def test_each_class_of_bad_file_has_its_own_message(mutate, field, words):
    problems = bad(mutate)
    assert any(p.startswith(field + ":") and words in p for p in problems), problems


def test_every_problem_is_reported_not_just_the_first():
    def many(d):
        d["rooms"][0]["colour"] = "red"
        d["rooms"][1]["door"] = [1, "x"]
        d["waypoints"][0]["pos"] = [float("inf"), 0]

    assert len(bad(many)) == 3


def test_semantic_problems_are_all_reported():
    def many(d):
        d["edges"].append(["end1", "ghost"])
        d["rooms"].append(dict(d["rooms"][0]))
        d["rooms"][1]["door"] = [40, 40]

    problems = bad(many)
    assert len(problems) >= 3
    assert {p.split(":")[0] for p in problems} >= {"edges[2].to", "rooms[2].id", "rooms[1].door"}


def test_error_summary_names_file_and_count():
    with pytest.raises(BuildingFileError) as info:
        building_from_data({**GOOD, "floors": 1, "colour": 2}, "house.yaml")
    s = str(info.value)
    assert s.startswith("house.yaml: ") and "1 more" in s and "pmnav validate" in s


def test_top_level_not_a_mapping():
    with pytest.raises(BuildingFileError, match="expected a mapping"):
        building_from_data([1, 2, 3], "list.yaml")


def test_file_errors_name_the_file(tmp_path):
    missing = tmp_path / "missing.yaml"
    with pytest.raises(BuildingFileError, match="missing.yaml: cannot read building file"):
        load_building(missing)
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: [unclosed\n")
    with pytest.raises(
        BuildingFileError, match=r"broken.yaml: line \d+, column \d+: not valid YAML"
    ):
        load_building(broken)
    with pytest.raises(BuildingFileError, match="no built-in building of that name"):
        load_building("no_such_building")


def test_floor_plan_file_must_exist(tmp_path):
    data = {**GOOD, "floor_plan": {"image": "plan.png", "metres_per_pixel": 0.05}}
    path = tmp_path / "b.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(BuildingFileError, match="floor_plan.image: file not found"):
        load_building(path)
    (tmp_path / "plan.png").write_bytes(b"not an image")
    with pytest.raises(BuildingFileError, match="floor_plan.image: .*not a PNG"):
        load_building(path)
    cv2.imwrite(str(tmp_path / "plan.png"), np.zeros((4, 4), np.uint8))
    assert load_building(path).floor_plan.metres_per_pixel == 0.05


def test_save_round_trips(tmp_path):
    b = building_from_data(GOOD)
    path = save_building(b, tmp_path / "out.yaml")
    again = load_building(path)
    assert again == b
    assert dump_building(again) == dump_building(b)


@pytest.mark.parametrize("name", builtin_buildings())
def test_builtin_buildings_load_and_round_trip(name, tmp_path):
    b = load_building(name)
    assert isinstance(b, Building)
    assert load_building(save_building(b, tmp_path / f"{name}.yaml")) == b


def test_no_bad_input_is_lost_loading_does_not_touch_the_file(tmp_path):
    path = tmp_path / "keep.yaml"
    text = "schema_version: 1\nname: keep\nwaypoints: []\nedges: []\nbogus: 1\n"
    path.write_text(text)
    with pytest.raises(BuildingFileError):
        load_building(path)
    assert path.read_text() == text


def test_lengths_use_positions():
    b = building_from_data(GOOD)
    g = b.corridor_graph()
    assert g.edges["start", "turn1"]["length"] == pytest.approx(math.dist((0, 0), (10, 0)))


def test_a_rooms_amenity_is_the_files_else_its_names():
    from pmnav_bt.map.amenities import room_amenity

    def room(**kw):
        d = {**GOOD, "rooms": [{"id": "r1", "door": GOOD["rooms"][0]["door"], **kw}]}
        return building_from_data(d, "b.yaml").rooms[0]

    assert room_amenity(room(name="Toilets")) == "toilet"
    assert room_amenity(room(name="Accessible WC")) == "toilet"
    assert room_amenity(room(name="Pharmacy")) is None
    assert room_amenity(room(name="Quiet Room", amenity="toilet")) == "toilet"
    assert room_amenity(room(name="Toilets Store", amenity="none")) is None
