"""Map parsing: room waypoints, segments, names, directions, text and JSON."""

from __future__ import annotations

import json
import math

import pytest

from pmnav_bt.errors import UnknownNameError
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.priori_map import MERGE_TOLERANCE, parse_building


def test_fig2_has_the_papers_segment(fig2_map):
    # Paper, Fig. 2: the plan starts on seg13(room14-room7).
    seg = fig2_map.segment("seg13")
    assert seg.name == "seg13(room14-room7)"
    assert fig2_map.segment("seg13(room14-room7)") is seg
    assert fig2_map.segment(" SEG 13 ") is seg
    assert fig2_map.segment(13) is seg


def test_segment_names_are_stable_across_parses(fig2):
    a = [s.name for s in parse_building(fig2).segments]
    b = [s.name for s in parse_building(fig2).segments]
    assert a == b


def test_segment_lookup_errors(fig2_map):
    with pytest.raises(UnknownNameError, match="seg1 to seg27"):
        fig2_map.segment("seg99")
    with pytest.raises(UnknownNameError, match="seg13 is seg13"):
        fig2_map.segment("seg13(room1-room2)")


def test_every_room_links_to_its_nearest_corridor_node(fig2, fig2_map):
    for r in fig2.rooms:
        place = fig2_map.places[r.id]
        node = fig2_map.nodes[place.node]
        assert r.id in node.rooms
        # The node sits on the centre line across from the door.
        assert math.dist(node.pos, r.door) == pytest.approx(fig2.corridor_width / 2, abs=0.35)


def test_segments_cover_each_corridor_exactly(fig2, fig2_map):
    for e in fig2.edges:
        total = sum(s.length for s in fig2_map.segments if s.corridor == (e.a, e.b))
        assert total == pytest.approx(math.dist(fig2.waypoint(e.a).pos, fig2.waypoint(e.b).pos))


def test_segments_are_cut_at_room_and_key_waypoints(fig2_map):
    for s in fig2_map.segments:
        for end in (s.a, s.b):
            n = fig2_map.nodes[end]
            assert n.is_key or n.rooms or n.landmarks
    # and the graph joins consecutive nodes only
    assert fig2_map.graph.number_of_edges() == len(fig2_map.segments)


def test_facing_doors_share_one_node():
    data = {
        "schema_version": 1,
        "name": "facing",
        "waypoints": [
            {"id": "s", "kind": "start", "pos": [0, 0]},
            {"id": "e", "kind": "end", "pos": [20, 0]},
        ],
        "edges": [["s", "e"]],
        "rooms": [
            {"id": "room2", "door": [10, 1.2]},
            {"id": "room1", "door": [10 + MERGE_TOLERANCE / 2, -1.2]},
            {"id": "room3", "door": [15, 1.2]},
        ],
    }
    pm = parse_building(building_from_data(data))
    assert pm.nodes["room1"].rooms == ("room1", "room2")  # named after the lower number
    assert [s.name for s in pm.segments] == ["seg1(s-room1)", "seg2(room1-room3)", "seg3(room3-e)"]
    assert pm.places["room2"].side == "left" and pm.places["room1"].side == "right"


def test_room_at_a_corridor_end_attaches_to_the_waypoint():
    data = {
        "schema_version": 1,
        "name": "end",
        "waypoints": [
            {"id": "s", "kind": "start", "pos": [0, 0]},
            {"id": "e", "kind": "end", "pos": [20, 0]},
        ],
        "edges": [["s", "e"]],
        "rooms": [{"id": "room9", "door": [21.2, 0]}],
    }
    pm = parse_building(building_from_data(data))
    assert pm.nodes["e"].rooms == ("room9",)
    assert pm.nodes["e"].visible and len(pm.segments) == 1


def test_directions_are_compass_words(fig2_map):
    text = [d.sentence() for d in fig2_map.directions]
    assert text[0].startswith("from start to turn1, the direction is south")
    assert any(t.startswith("from turn1 to turn2, the direction is east") for t in text)
    assert any(t.startswith("from turn2 to branch1, the direction is north") for t in text)


def test_text_has_everything_a_prompt_needs(fig2_map):
    t = fig2_map.to_text()
    for needle in (
        "seg13(room14-room7)",
        "room17: One-Stop Service Centre",
        "from start to turn1, the direction is south",
        "elevator1",
        "branch1: branch",
    ):
        assert needle in t


def test_json_is_complete_and_serialisable(fig2, fig2_map):
    d = json.loads(json.dumps(fig2_map.to_dict()))
    assert len(d["segments"]) == len(fig2_map.segments)
    assert {r["id"] for r in d["rooms"]} == {r.id for r in fig2.rooms}
    seg13 = d["segments"][12]
    assert seg13["name"] == "seg13(room14-room7)" and seg13["compass"] == "east"


def test_locate_projects_onto_the_nearest_segment(fig2_map):
    loc = fig2_map.locate(22.0, 0.3)
    assert loc.segment.name == "seg13(room14-room7)"
    assert loc.t == pytest.approx(0.5) and loc.offset == pytest.approx(0.3)
