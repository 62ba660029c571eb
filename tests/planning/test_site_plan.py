"""Planning across levels: legs joined by lift rides, the lift chosen by total cost."""

from __future__ import annotations

import networkx as nx
import pytest
from site_kit import level_data, two_level_site

from pmnav_bt.errors import PlanningError, UnknownNameError
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.site import Level, LiftLink, Site, load_site, site_from_data
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.planning.resolve import resolve_site_room
from pmnav_bt.planning.site_plan import LIFT_CALL_M, LIFT_LEVEL_M, SitePlanner, out_of_lift
from pmnav_bt.seams import PlanConstraints


@pytest.fixture(scope="module")
def twin():
    return parse_site(site_from_data(two_level_site(), "s.yaml"))


@pytest.fixture(scope="module")
def hospital():
    return parse_site(load_site("hospital_2l"))


def test_two_level_plan_has_the_ride_between_its_legs(twin):
    p = SitePlanner().plan(twin, "L1", "start", "room202")
    assert [leg.level for leg in p.legs] == ["L1", "L2"]
    (ride,) = p.rides
    assert (ride.from_level, ride.to_level) == ("L1", "L2")
    first, second = p.legs
    assert first.plan.goal == twin.site.lift(ride.lift).lobbies["L1"]
    assert first.plan.goal_kind == "landmark" and first.plan.steps[-1].action.value == "arrive"
    assert second.plan.start.description.startswith(twin.site.lift(ride.lift).lobbies["L2"])
    assert second.plan.goal == "room202" and second.plan.goal_kind == "room"
    steps = p.step_texts()
    ride_at = steps.index(f"{{{ride.lift}: take the lift to level L2}}")
    assert steps[ride_at - 1] == f"{{{first.plan.goal}: arrive}}"
    assert steps[-1] == "{room202: arrive}"


def test_the_nearer_lift_is_chosen(twin):
    # From the west end to a room near lift A's shaft: lift A (x=5), not lift B (x=35).
    assert SitePlanner().plan(twin, "L1", "start", "room201").rides[0].lift == "liftA"
    # From the east end to a room near lift B: lift B.
    assert SitePlanner().plan(twin, "L1", "end1", "room202").rides[0].lift == "liftB"


def test_the_lift_is_chosen_by_total_cost_not_the_nearest_lobby(twin):
    # From x=19 on L1, lift A's lobby (x=5) is 14 m away and lift B's (x=35) 16 m; the goal
    # on L2 is at x=34, 29 m from lift A but 1 m from lift B: lift B costs less in all.
    p = SitePlanner().plan(twin, "L1", "19,0", "room202")
    assert p.rides[0].lift == "liftB"
    assert p.cost == pytest.approx(16.0 + LIFT_CALL_M + LIFT_LEVEL_M + 5.0)


def test_a_one_level_goal_plans_as_the_building_does():
    b = load_building("fig2_hospital")
    sm = parse_site(load_site("fig2_hospital"))
    p = SitePlanner().plan(sm, "L1", "seg13", "room17")
    assert not p.rides and len(p.legs) == 1
    assert p.legs[0].plan == GraphPlanner().plan(parse_building(b), "seg13", "room17")
    assert p.text() == p.legs[0].plan.text()


def test_a_goal_on_the_start_level_needs_no_ride(twin):
    p = SitePlanner().plan(twin, "L2", "start", "room202")
    assert not p.rides and p.legs[0].level == "L2"


def test_rides_change_lifts_where_no_lift_serves_both_levels():
    data = two_level_site()
    data["levels"].append(
        {"name": "L3", "elevation": 8.0, "building": level_data("top", {"room301": 20}, {"lC": 30})}
    )
    data["levels"][1]["building"]["landmarks"].append(
        {"id": "lC", "kind": "elevator", "pos": [30.0, -1.2]}
    )
    data["lifts"].append({"id": "liftC", "lobbies": {"L2": "lC", "L3": "lC"}})
    sm = parse_site(site_from_data(data, "s.yaml"))
    # From x=0: lift A (5 m away) then 25 m on L2 to lift C beats lift B (35 m, then 5 m).
    p = SitePlanner().plan(sm, "L1", "start", "room301")
    assert [(r.lift, r.from_level, r.to_level) for r in p.rides] == [
        ("liftA", "L1", "L2"),
        ("liftC", "L2", "L3"),
    ]
    assert [leg.level for leg in p.legs] == ["L1", "L2", "L3"]
    change = p.legs[1].plan  # the change of lifts on L2 is a leg of its own
    assert change.start.description.startswith("lA") and change.goal == "lC"
    assert p.cost == pytest.approx(5 + 25 + 10 + 2 * (LIFT_CALL_M + LIFT_LEVEL_M))


def test_an_unreachable_level_is_a_planning_error():
    # Built without validation: L2 has no lift (load_site refuses such a site).
    b1 = parse_building(load_building("fig2_hospital")).building
    lonely = site_from_data(two_level_site(), "s.yaml").levels[1]
    site = Site("odd", (Level("L1", 0.0, b1), lonely), (LiftLink("x", "", {"L1": "elevator1"}),))
    with pytest.raises(PlanningError, match=r"room202 on L2 cannot be reached .* on L1: no lift"):
        SitePlanner().plan(parse_site(site), "L1", "seg13", "room202")


def test_blocked_corridors_on_the_start_level_can_cut_off_every_lift(twin):
    pm = twin.maps["L1"]
    every = frozenset(s.index for s in pm.segments)
    shut = PlanConstraints(blocked_segments=every)
    with pytest.raises(PlanningError, match="no lift .liftA, liftB. reached from there"):
        SitePlanner().plan(twin, "L1", "room102", "room201", shut)


def test_ride_out_of_the_lift_faces_the_corridor(hospital):
    p = SitePlanner().plan(hospital, "L1", "start", "Laboratory")
    # Lift A's doors are on the south wall: out of the lift the robot faces north.
    assert p.legs[1].plan.start.heading == pytest.approx(1.5708, abs=1e-3)


def test_plan_json_lists_steps_with_the_ride(hospital):
    d = SitePlanner().plan(hospital, "L1", "start", "room208").to_dict()
    assert d["goal"] == {"level": "L2", "room": "room208", "name": "Laboratory"}
    assert d["rides"][0]["text"] in d["steps"]


# -- goal names across levels ----------------------------------------------------------------


def test_a_name_on_one_level_resolves_there(hospital):
    assert resolve_site_room(hospital, "pharmacy") == ("L1", "room102")
    assert resolve_site_room(hospital, "lab") == ("L2", "room208")


def test_a_name_on_two_levels_lists_them(hospital):
    with pytest.raises(UnknownNameError, match="on 2 levels: L1 .*room113.*; L2 .*room212") as e:
        resolve_site_room(hospital, "Toilets")
    assert "'L1/Toilets' or 'Toilets on L1'" in str(e.value)
    assert e.value.candidates == ["L1/room113", "L2/room212"]


@pytest.mark.parametrize(
    "name", ["L2/Toilets", "l2 / toilets", "Toilets on L2", "toilets on level L2"]
)
def test_a_qualified_name_picks_its_level(hospital, name):
    assert resolve_site_room(hospital, name) == ("L2", "room212")


def test_a_slash_or_on_that_names_no_level_is_part_of_the_name(hospital):
    with pytest.raises(UnknownNameError, match="no room called 'Toilets on L9' on any level"):
        resolve_site_room(hospital, "Toilets on L9")


def test_an_unknown_name_offers_rooms_of_every_level(hospital):
    with pytest.raises(UnknownNameError, match="closest: .*L1/room10") as e:
        resolve_site_room(hospital, "room10")
    assert all("/" in c for c in e.value.candidates)


def test_a_landmark_name_says_so_with_its_level(hospital):
    with pytest.raises(UnknownNameError, match=r"landmark .* \(on level L2\)"):
        resolve_site_room(hospital, "Nurses' Station")


def test_landmark_goal_keeps_room_plans_unchanged(fig2_map):
    g = GraphPlanner()
    room_plan = g.plan(fig2_map, "seg13", "room17")
    assert room_plan.goal_kind == "room" and room_plan.to_dict()["goal"]["room"] == "room17"
    lift = g.plan_to_landmark(fig2_map, "seg13", "elevator1")
    assert lift.goal == "elevator1" and lift.goal_name == "Elevator A"
    assert lift.steps[-1].look_for == "elevator1" and lift.steps[-1].action.value == "arrive"
    with pytest.raises(UnknownNameError, match="no landmark 'room17'"):
        g.plan_to_landmark(fig2_map, "seg13", "room17")


@pytest.mark.parametrize(
    "start, goal",
    [
        ("start", "Laboratory"),
        ("12,0,180", "Ward 7"),
        ("room119", "L2/Toilets"),
        ("seg5", "room210"),
    ],
)
def test_legs_are_the_graph_planners_plans(hospital, start, goal):
    p = SitePlanner().plan(hospital, "L1", start, goal)
    g = GraphPlanner()
    (ride,) = p.rides
    lobby = hospital.site.lift(ride.lift).lobbies["L1"]
    first = g.plan_to_landmark(hospital.maps["L1"], start, lobby)
    last = g.plan(hospital.maps["L2"], out_of_lift(hospital, ride.lift, "L2"), p.goal)
    for got, want in zip(p.legs, (first, last), strict=True):
        assert got.plan.nodes == want.nodes
        assert [s.text() for s in got.plan.steps] == [s.text() for s in want.steps]
        assert got.plan.length == pytest.approx(want.length)
        assert got.plan.initial_action is want.initial_action


def _bench_module():
    import importlib.util
    from pathlib import Path

    bench = Path(__file__).parents[2] / "benchmarks" / "bench_plan_levels.py"
    spec = importlib.util.spec_from_file_location("bench_plan_levels", bench)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # its generated site: levels of another layout each
    return module


def _random_lifts_site(levels: int, rooms: int, seed: int):
    """The benchmark's levels with three lifts of random reach: each serves a random set
    of levels, its lobby a random elevator on each (two lifts share one: a level has two),
    so plans must sometimes change lifts on a level between."""
    import random

    from pmnav_bt.errors import BuildingFileError

    data = _bench_module().site_data(levels, rooms, seed)
    rng = random.Random(seed)
    elevators = {
        lv["name"]: [lm["id"] for lm in lv["building"]["landmarks"] if lm["kind"] == "elevator"]
        for lv in data["levels"]
    }
    names = list(elevators)
    while True:  # until the lifts join every level (what a site file must)
        banks = {lv: rng.sample(e, len(e)) for lv, e in elevators.items()}  # lift j: bank j
        data["lifts"] = [
            {
                "id": f"lift{j + 1}",
                "lobbies": {lv: banks[lv][j % len(banks[lv])] for lv in rng.sample(names, k)},
            }
            for j, k in enumerate(rng.choices(range(2, levels + 1), k=3))
        ]
        try:
            return parse_site(site_from_data(data, "s.yaml"))
        except BuildingFileError:
            continue


def _reference(sm, here, start, there, room, constraints):
    """Every lobby of the site, every leg planned in full by the graph planner: the
    lobby graph's cheapest cost from the start to the goal, and the cheapest cost with
    each lift of the start level taken first (inf where none leads to the goal)."""
    g, sp = GraphPlanner(), SitePlanner()
    ref = nx.DiGraph()
    for lift in sm.site.lifts:
        for lv, lobby in lift.lobbies.items():
            for lv2 in set(lift.lobbies) - {lv}:
                ref.add_edge((lv, lift.id), (lv2, lift.id), w=sp.ride_cost(sm.site, lv, lv2))
            graph = sm.maps[lv].graph
            if lv == here:  # the start level's corridors as the constraints leave them
                graph = nx.subgraph_view(
                    graph,
                    filter_edge=lambda u, v, gr=graph: gr.edges[u, v]["segment"]
                    not in constraints.blocked_segments,
                )
            for other in sm.site.lifts_at(lv):
                a, b = sm.lobby_nodes[(lift.id, lv)], sm.lobby_nodes[(other.id, lv)]
                try:
                    d = nx.shortest_path_length(graph, a, b, weight="length")
                except nx.NetworkXNoPath:
                    continue
                ref.add_edge((lv, lift.id), (lv, other.id), w=d)
            pm = sm.maps[lv]
            try:
                if lv == here:
                    d = g.plan_to_landmark(pm, start, lobby, constraints).length
                    ref.add_edge("S", (lv, lift.id), w=d)
                if lv == there:
                    d = g.plan(pm, out_of_lift(sm, lift.id, there), room).length
                    ref.add_edge((lv, lift.id), "G", w=d)
            except PlanningError:
                continue

    def cheapest(graph) -> float:
        try:
            return nx.dijkstra_path_length(graph, "S", "G", weight="w")
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            return float("inf")

    by_first = {}
    for lift in sm.site.lifts_at(here):
        only = nx.restricted_view(
            ref, [], [("S", n) for n in ref.successors("S") if n != (here, lift.id)]
        ) if "S" in ref else ref
        by_first[lift.id] = cheapest(only)
    return cheapest(ref), by_first


@pytest.mark.parametrize(
    "make",
    [
        lambda: parse_site(site_from_data(_bench_module().site_data(3, 150, 7), "s.yaml")),
        lambda: _random_lifts_site(4, 120, 5),
        lambda: _random_lifts_site(5, 80, 11),
    ],
    ids=["bench-3x150", "random-lifts-4x120", "random-lifts-5x80"],
)
def test_the_chosen_lifts_are_the_full_searchs_on_generated_sites(make):
    """Against every lift tried in full, every leg planned by the graph planner (the plan
    reads lobby trees and expands few lobbies; it must not choose wrong): the same cost,
    the same first lift where one is cheapest, legs and rides that add up to the cost;
    a quarter of the plans with corridors of the start level blocked."""
    import random

    sm = make()
    rng = random.Random(3)
    sp = SitePlanner()
    chosen = 0
    for i in range(24):
        here, there = rng.sample(sm.site.level_names, 2)
        n_segments = len(sm.maps[here].segments)
        start = f"seg{rng.randint(1, n_segments)}"
        room = rng.choice(sm.maps[there].building.rooms).id
        constraints = PlanConstraints()
        if i % 4 == 3:
            blocked = frozenset(rng.sample(range(1, n_segments + 1), 4))
            constraints = PlanConstraints(blocked_segments=blocked)
        best, by_first = _reference(sm, here, start, there, room, constraints)
        if best == float("inf"):
            with pytest.raises(PlanningError):
                sp.plan(sm, here, start, f"{there}/{room}", constraints)
            continue
        p = sp.plan(sm, here, start, f"{there}/{room}", constraints)
        assert p.cost == pytest.approx(best)
        rides = sum(sp.ride_cost(sm.site, r.from_level, r.to_level) for r in p.rides)
        assert p.length + rides == pytest.approx(p.cost)
        first = p.rides[0].lift
        assert by_first[first] == pytest.approx(best)
        cheapest = [k for k, c in by_first.items() if c <= best + 1e-6]
        if len(cheapest) == 1:
            assert first == cheapest[0]
            chosen += 1
    assert chosen >= 5  # the lift choice was put to the test, not only ties
