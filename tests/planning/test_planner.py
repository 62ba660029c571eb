"""Graph planner: paper-style steps, action prediction, forks, sides, starts and errors."""

from __future__ import annotations

import json
import math
from itertools import pairwise

import pytest

from pmnav_bt.errors import UnknownNameError
from pmnav_bt.geometry import Action
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.planning.resolve import resolve_start
from pmnav_bt.seams import PlanConstraints, Pose2D

planner = GraphPlanner()


def test_fig2_plan_from_seg13_to_room17(fig2_map):
    p = planner.plan(fig2_map, "seg13", "room17")
    texts = [s.text() for s in p.steps]
    # The paper's action prediction: {room8: go straight} -> {turn2: turn left}
    assert "{room8: go straight} -> {turn2: turn left}" in texts
    assert "{turn2: turn left}" in texts
    assert texts[-1] == "{room17: arrive}"
    branch = next(s for s in p.steps if s.landmark == "branch1")
    assert branch.action is Action.TURN_RIGHT and branch.fork is not None
    assert branch.fork.options == (Action.TURN_LEFT,)
    assert p.steps[-1].side == "left"  # room17's door is on the left going east
    assert p.length == pytest.approx(48.0)
    assert p.nodes[0] == "room7" and p.nodes[-1] == "room17"


def test_unseen_steps_are_never_the_only_warning(fig2_map, loop_map):
    # Every unseen turn/fork is predicted by the visible step just before it, when one exists.
    for pm, start, goal in ((fig2_map, "start", "room21"), (loop_map, "start", "room10")):
        steps = planner.plan(pm, start, goal).steps
        for prev, s in pairwise(steps):
            if not s.visible and prev.visible:
                assert prev.predicts == (s.landmark, s.action)


def test_gap_filling_respects_max_gap(fig2_map):
    for gap in (5.0, 10.0, 20.0):
        p = GraphPlanner(max_gap=gap).plan(fig2_map, "start", "room17")
        # Landmarks in fig2 are at most 8 m apart, so every gap can be met.
        assert max(s.distance for s in p.steps) <= max(gap, 8.0) + 1e-9
    assert len(GraphPlanner(max_gap=5).plan(fig2_map, "start", "room17").steps) > len(
        GraphPlanner(max_gap=20).plan(fig2_map, "start", "room17").steps
    )


def test_step_distances_add_up_to_the_route(fig2_map):
    p = planner.plan(fig2_map, "start", "room17")
    assert sum(s.distance for s in p.steps) == pytest.approx(p.length)


def test_goal_by_name_alias_and_spacing(fig2_map):
    for name in (
        "room17",
        "Room 17",
        "ONE-STOP SERVICE  CENTRE",
        "ossc",
        "117 One-Stop Service Centre",
    ):
        assert planner.plan(fig2_map, "seg13", name).goal == "room17"


def test_unknown_goal_lists_candidates(fig2_map):
    with pytest.raises(UnknownNameError) as info:
        planner.plan(fig2_map, "seg13", "Pharmcy")
    assert "room2 (Pharmacy)" in info.value.candidates
    assert "closest" in str(info.value)


def test_landmark_goal_is_a_clear_error(fig2_map):
    with pytest.raises(UnknownNameError, match="landmark"):
        planner.plan(fig2_map, "seg13", "elevator")


def test_ambiguous_goal_lists_both(fig2):
    data = fig2.to_dict()
    data["rooms"][0]["name"] = "Pharmacy"  # room1 and room2 both called Pharmacy now
    from pmnav_bt.map.building import building_from_data

    pm = parse_building(building_from_data(data))
    with pytest.raises(UnknownNameError, match="ambiguous") as info:
        planner.plan(pm, "seg13", "pharmacy")
    assert len(info.value.candidates) == 2


def test_pose_start_with_heading_gives_initial_turn(fig2_map):
    # On seg13 facing west; room17 lies east: turn around first.
    p = planner.plan(fig2_map, "22,0,180", "room17")
    assert p.initial_action is Action.TURN_AROUND
    assert planner.plan(fig2_map, "22,0,0", "room17").initial_action is Action.GO_STRAIGHT
    assert planner.plan(fig2_map, "22,0,90", "room17").initial_action is Action.TURN_RIGHT


def test_on_a_tie_the_plan_goes_the_way_the_robot_faces():
    from pmnav_bt.map.building import building_from_data

    data = {
        "schema_version": 1,
        "name": "square",
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [-5, 0]},
            {"id": "branch1", "kind": "branch", "pos": [0, 0]},
            {"id": "turn1", "kind": "turn", "pos": [20, 0]},
            {"id": "turn2", "kind": "turn", "pos": [20, 20]},
            {"id": "turn3", "kind": "turn", "pos": [0, 20]},
        ],
        "edges": [
            ["start", "branch1"],
            ["branch1", "turn1"],
            ["turn1", "turn2"],
            ["turn2", "turn3"],
            ["turn3", "branch1"],
        ],
        "rooms": [{"id": "room1", "door": [10, 21.2]}],
    }
    pm = parse_building(building_from_data(data))
    east = planner.plan(pm, "10,0,0", "room1")
    west = planner.plan(pm, "10,0,180", "room1")
    assert east.length == pytest.approx(west.length) == pytest.approx(40.0)
    assert east.nodes[0] == "turn1" and east.initial_action is Action.GO_STRAIGHT
    assert west.nodes[0] == "branch1" and west.initial_action is Action.GO_STRAIGHT


def test_start_at_the_goal_is_one_arrive_step(fig2_map):
    p = planner.plan(fig2_map, "room18", "room18")
    assert [s.text() for s in p.steps] == ["{room18: arrive}"]
    assert p.length == 0.0


@pytest.mark.parametrize("bad", ["seg0", "nowhere", "1,2,3,4", "300,300"])
def test_bad_starts_are_clear_errors(fig2_map, bad):
    with pytest.raises(UnknownNameError):
        resolve_start(fig2_map, bad)


def test_start_forms(fig2_map):
    assert resolve_start(fig2_map, "seg13").t == 0.5
    w = resolve_start(fig2_map, "turn2")
    assert w.segment.a == "turn2" or w.segment.b == "turn2"
    r = resolve_start(fig2_map, "Cashier")
    assert "room18" in (r.segment.a, r.segment.b)
    p = resolve_start(fig2_map, "22.5, 0.2, 90")
    assert p.heading == pytest.approx(math.pi / 2)


def test_json_form(fig2_map):
    p = planner.plan(fig2_map, "seg13", "room17")
    d = json.loads(p.to_json())
    assert d["goal"] == {"room": "room17", "name": "One-Stop Service Centre"}
    room8 = next(s for s in d["steps"] if s["landmark"] == "room8")
    assert room8["predicts"] == {"turn2": "turn left"}
    assert d["steps"][-1]["action"] == "arrive"
    assert d["path"][0] == list(p.start.position)


def test_text_form(fig2_map):
    t = planner.plan(fig2_map, "seg13", "room17").text()
    assert t.splitlines()[0].startswith("Plan in fig2_hospital: seg13(room14-room7) -> room17")
    assert "{room8: go straight} -> {turn2: turn left}" in t
    assert "fork: turn right" in t


def test_loop_takes_the_shorter_way_round(loop_map):
    # room13 (Art Room, east side) from the west side: round the north, not the south.
    p = planner.plan(loop_map, "seg16", "room13")
    assert "branch2" in p.nodes and "branch1" not in p.nodes


def test_avoided_landmarks_are_not_used_as_steps(fig2_map):
    p = planner.plan(fig2_map, "seg13", "room17")
    assert any(s.look_for == "room8" for s in p.steps)
    q = planner.plan(
        fig2_map, "seg13", "room17", PlanConstraints(avoid_landmarks=frozenset({"room8"}))
    )
    assert all(s.look_for != "room8" for s in q.steps)
    # turn2 is then predicted by the visible landmark before room8
    pred = next(s for s in q.steps if s.predicts and s.predicts[0] == "turn2")
    assert pred.look_for in ("room7", "room15")


def test_the_goal_is_never_avoided(fig2_map):
    q = planner.plan(
        fig2_map, "seg13", "room17", PlanConstraints(avoid_landmarks=frozenset({"room17"}))
    )
    assert q.steps[-1].look_for == "room17"


def test_blocked_segments_are_routed_around(loop_map):
    p = planner.plan(loop_map, "seg16", "room13")
    used = {loop_map.graph.edges[u, v]["segment"] for u, v in pairwise(p.nodes)}
    q = planner.plan(loop_map, "seg16", "room13", PlanConstraints(blocked_segments=frozenset(used)))
    assert q.length > p.length and "branch1" in q.nodes


def test_no_route_is_a_planning_error(fig2_map):
    from pmnav_bt.errors import PlanningError

    with pytest.raises(PlanningError):
        planner.plan(
            fig2_map, "seg13", "room17", PlanConstraints(blocked_segments=frozenset({14, 12}))
        )


def test_a_pose_start_is_typed_radians_and_matches_the_typed_text(fig2_map):
    """Inside the loop the start is a Pose2D (radians); a person types degrees."""
    import math

    typed = planner.plan(fig2_map, Pose2D(22.0, 0.0, math.pi / 2), "room17")
    text = planner.plan(fig2_map, "22,0,90", "room17")
    assert typed.initial_action is text.initial_action is Action.TURN_RIGHT
    assert typed.nodes == text.nodes


def _two_signs_at_one_spot(end=(20.0, 0.0)):
    """A straight corridor with two signs at one point of its wall (and a room near the
    start): the map links both to one point of the centre line, a 0 m segment apart."""
    from pmnav_bt.map.building import building_from_data

    ux, uy = end[0] / math.hypot(*end), end[1] / math.hypot(*end)
    at = lambda s, off: [s * ux - off * uy, s * uy + off * ux]  # noqa: E731
    return parse_building(
        building_from_data(
            {
                "schema_version": 1,
                "name": "two_signs",
                "waypoints": [
                    {"id": "start", "kind": "start", "pos": [0, 0]},
                    {"id": "end1", "kind": "end", "pos": list(end)},
                ],
                "edges": [["start", "end1"]],
                "rooms": [{"id": "room1", "door": at(2.0, 1.2), "sign": "101"}],
                "landmarks": [
                    {"id": "signa", "kind": "sign", "pos": at(10.0, 1.2), "sign": "Exit A"},
                    {"id": "signb", "kind": "sign", "pos": at(10.0, 1.2), "sign": "Exit B"},
                ],
            }
        )
    )


@pytest.mark.parametrize("end", [(20.0, 0.0), (-20.0, 0.0), (0.0, -20.0)])
def test_two_landmarks_at_one_spot_are_one_place_on_a_straight_route(end):
    pm = _two_signs_at_one_spot(end)
    zero = [s for s in pm.segments if s.length < 1e-9]
    assert len(zero) == 1  # the map keeps both landmarks, a 0 m segment apart
    assert zero[0].heading == pytest.approx(math.atan2(end[1], end[0]))  # along its corridor
    for gap in (2.0, 8.0):  # a short gap asks for every landmark on the way
        p = GraphPlanner(max_gap=gap).plan(pm, "end1", "room1")
        assert all(s.distance > 1e-6 for s in p.steps), [s.text() for s in p.steps]
        actions = [s.action for s in p.steps]
        assert actions == [Action.GO_STRAIGHT] * (len(actions) - 1) + [Action.ARRIVE]
        assert sum(s.distance for s in p.steps) == pytest.approx(p.length) == pytest.approx(18.0)


@pytest.mark.parametrize("kind", ["sign", "fire_door"])
def test_a_fire_door_is_never_a_step_to_look_for(kind):
    """A sign 10 m along the corridor is a step to look for; a fire door there has no
    sign to read, so the plan never asks the robot to find it (it drives through)."""
    from pmnav_bt.map.building import building_from_data

    pm = parse_building(
        building_from_data(
            {
                "schema_version": 1,
                "name": "one_corridor",
                "waypoints": [
                    {"id": "start", "kind": "start", "pos": [0, 0]},
                    {"id": "end1", "kind": "end", "pos": [20, 0]},
                ],
                "edges": [["start", "end1"]],
                "rooms": [{"id": "room1", "door": [18, 1.2], "sign": "101"}],
                "landmarks": [{"id": "thing", "kind": kind, "pos": [10, 1.2], "sign": "FD1"}],
            }
        )
    )
    p = GraphPlanner(max_gap=2.0).plan(pm, "start", "room1")  # asks for every landmark
    looked_for = {s.look_for for s in p.steps}
    assert ("thing" in looked_for) is (kind == "sign")
    assert p.steps[-1].look_for == "room1"
