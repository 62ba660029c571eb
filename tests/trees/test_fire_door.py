"""A fire door shut on the route, in the simulator: with no way round the run ends
DOOR_CLOSED naming the door; with one, the robot goes round it."""

from __future__ import annotations

import pytest
from building_kit import with_landmark

from pmnav_bt.experiments.evaluation import custom_episode, run_episode
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.building import Landmark, save_building
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.testing.oracle import oracle_config

pytestmark = [pytest.mark.world, pytest.mark.timeout(600)]

SHUT = "world.fire_doors_closed=1"


def _with_fire_door(tmp_path, name: str, pos: tuple[float, float]) -> str:
    door = Landmark(id="fd1", kind="fire_door", name="FD-1", pos=pos)
    return str(save_building(with_landmark(load_building(name), door), tmp_path / f"{name}.yaml"))


def test_a_shut_fire_door_on_the_only_way_ends_door_closed_naming_it(tmp_path):
    # straight_office: room6 (24 m east of the start) lies behind the door at x = 15.25.
    path = _with_fire_door(tmp_path, "straight_office", (15.25, 0.0))
    ep = custom_episode(path, "room6")
    run = run_episode(ep, oracle_config(SHUT), out_dir=tmp_path, plot=False)
    r = run.result
    assert not r.success
    assert r.collisions == 0
    assert r.failure_reason.startswith(FailureCode.DOOR_CLOSED.value), r.failure_reason
    assert "fire door FD-1" in r.failure_reason


def test_a_shut_fire_door_with_a_way_round_is_gone_round(tmp_path):
    # loop_school: room9 lies 66 m away round the west of the ring, 70 m round the east;
    # the door shuts the west way on seg19 (turn4-room1), 12 m from branch1.
    path = _with_fire_door(tmp_path, "loop_school", (3.0, 0.0))
    ep = custom_episode(path, "room9", start="15,-6,90")
    cfg = oracle_config(SHUT, "tree.budget_actions=3000")
    run = run_episode(ep, cfg, out_dir=tmp_path, plot=False)
    r = run.result
    assert r.success, r.failure_reason
    assert r.collisions == 0
    assert "replan after DOOR_CLOSED: fire door FD-1" in run.tree_log.read_text()
