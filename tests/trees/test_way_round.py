"""A corridor closed on the route, in the simulator: the robot sees the barrier, waits
out the patience, marks the corridor blocked, goes round the ring after one replan for
it, and arrives."""

from __future__ import annotations

import dataclasses
import re

import pytest

from pmnav_bt.experiments.evaluation import custom_episode, run_episode
from pmnav_bt.testing.oracle import oracle_config

pytestmark = [pytest.mark.world, pytest.mark.timeout(600)]


def test_a_closed_corridor_is_gone_round_after_one_replan(tmp_path):
    # loop_school: room9 lies 66 m away round the west of the ring, 70 m round the east;
    # seg19 (turn4-room1), on the west way 12 m from branch1, has a barrier across it.
    ep = custom_episode("loop_school", "room9", start="15,-6,90")
    ep = dataclasses.replace(ep, blocked=("seg19",))
    run = run_episode(ep, oracle_config("tree.budget_actions=3000"), out_dir=tmp_path, plot=False)
    r = run.result
    assert r.success, r.failure_reason
    assert r.collisions == 0
    text = run.tree_log.read_text()
    # one replan for the barrier (a search may fail on the long way round and have its
    # own), and never another: the robot did not come back to it
    blocked = set(re.findall(r"replan after BLOCKED[^\"]*", text))
    assert len(blocked) == 1, blocked
    assert "the corridor between turn4 and room1 blocked for" in blocked.pop()
