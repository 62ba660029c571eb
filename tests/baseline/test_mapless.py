"""The map-less baseline on the simulator: it finds a room it was never shown the way to,
it cannot read the priori-map, and it fails with a code when there is nothing to find
(the oracle grounder, by name: these check the tree, not perception)."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.experiments.evaluation import custom_episode, run_episode
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.signs_only import MapAccessError, SignsOnly
from pmnav_bt.testing.doubles import FakeBase
from pmnav_bt.testing.oracle import oracle_config
from pmnav_bt.trees.mapless import build_mapless_tree
from pmnav_bt.trees.runner import make_context, run_tree

pytestmark = pytest.mark.timeout(240)
MAPLESS = "tree.variant=mapless"


def test_it_explores_down_the_corridor_and_stops_at_the_door(tmp_path):
    # At the t_school entrance room 3's sign is 14 m ahead, too far to read: the robot
    # must explore (look around, drive to a frontier, look again) before it sees it.
    ep = custom_episode("t_school", "room3", start="0,-18,90")
    run = run_episode(ep, oracle_config(MAPLESS), out_dir=tmp_path)
    r = run.result
    assert r.success, r.failure_reason
    assert r.collisions == 0 and r.distance_to_goal == 0.0
    assert r.path_length >= r.shortest_path_length
    assert r.steps > 60  # more than the straight drive: it looked around on the way
    assert run.plot.exists()


def test_it_gets_the_sign_vocabulary_and_nothing_of_the_map():
    b = load_building("t_school")
    ctx = make_context(FakeBase(), parse_building(b), oracle_config(MAPLESS))
    assert isinstance(ctx.pm, SignsOnly) and ctx.planner is None
    known = ctx.pm.building
    assert known.waypoints == () and known.edges == () and known.floor_plan is None
    assert all(math.isnan(r.door[0]) for r in known.rooms)
    assert [r.sign_text for r in known.rooms] == [r.sign_text for r in b.rooms]
    for attr in ("segments", "nodes", "places", "graph", "segment"):
        with pytest.raises(MapAccessError):
            getattr(ctx.pm, attr)


def test_the_tree_refuses_a_context_with_the_priori_map(fig2_map):
    ctx = make_context(FakeBase(), fig2_map, oracle_config())
    with pytest.raises(ValueError, match="map-free"):
        build_mapless_tree(ctx, "room17")


def test_an_unknown_room_is_an_invalid_goal():
    b = load_building("t_school")
    ctx = make_context(FakeBase(), parse_building(b), oracle_config(MAPLESS))
    outcome = run_tree(ctx, "room99")
    assert not outcome.success and outcome.failure.code is FailureCode.INVALID_GOAL


def test_a_room_whose_sign_is_never_readable_ends_with_the_budget():
    ep = custom_episode("t_school", "room6", start="0,-18,90")
    cfg = oracle_config(
        MAPLESS, "grounder.hidden=[room6]", "tree.budget_actions=120", "tree.budget_path_factor=0.1"
    )
    r = run_episode(ep, cfg, plot=False).result
    assert not r.success
    assert r.failure_reason.startswith("BUDGET_EXCEEDED"), r.failure_reason
    assert r.steps <= 125
