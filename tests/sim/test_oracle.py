"""The oracle follows the free-space geodesic with ground truth: SR 100, SPL >= 95."""

from __future__ import annotations

import contextlib
import dataclasses
import math

import pytest

from pmnav_bt.eval.metrics import aggregate_by_tier
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.episodes import (
    TIERS,
    EpisodeGenerationError,
    generate_episodes,
    shortest_path_points,
)
from pmnav_bt.sim.oracle import ORACLE_TICK, evaluate_oracle, goal_fields, run_oracle
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.world import SimWorld

PER_TIER = 5


def _episodes(name: str, seed: int = 11):
    out = []
    for tier in TIERS:
        # Some structures have no episodes of a tier (tested in test_episodes).
        with contextlib.suppress(EpisodeGenerationError):
            out += generate_episodes(name, tier, PER_TIER, seed=seed)
    return out


@pytest.mark.parametrize("name", builtin_buildings())
def test_oracle_scores_sr_100_and_spl_95(name):
    episodes = _episodes(name)
    assert len(episodes) >= PER_TIER
    results = evaluate_oracle(name, episodes, trace=True)
    table = aggregate_by_tier(results)
    for row in table.rows:
        assert row.sr == 100.0, (name, row)
        assert row.spl >= 95.0, (name, row)
    for r in results:
        assert r.failure_reason is None and r.collisions == 0 and r.people_contacts == 0
        assert r.distance_to_goal == 0.0 and r.distance_to_door <= 1.0
        # The geodesic is a lower bound the oracle meets (it keeps 5 cm more clearance
        # and ends 5 cm inside the success disc).
        lo = r.shortest_path_length - 0.03
        assert lo <= r.path_length <= 1.02 * r.shortest_path_length + 0.15
        assert r.path_length <= r.route_length - 0.3  # shorter than the corridor route
        assert len(r.trace) == r.steps + 1


@pytest.fixture(scope="module")
def fig2_world():
    b = load_building("fig2_hospital")
    with SimWorld(b, ceiling=False) as w:
        yield parse_building(b), w


def _base(world):
    return SimBase(
        world, SimClock(tick=ORACLE_TICK), width=16, height=12, depth=False, segmentation=False
    )


def test_step_budget_ends_the_run(fig2_world):
    pm, world = fig2_world
    ep = dataclasses.replace(generate_episodes(pm, "hard", 1, seed=1)[0], step_budget=10)
    base = _base(world)
    try:
        r = run_oracle(base, pm, ep)
    finally:
        base.close()
    assert not r.success and r.spl == 0.0 and r.steps == 10
    assert "budget" in r.failure_reason


def test_blocked_path_is_a_failure_with_a_reason(fig2_world):
    pm, world = fig2_world
    ep = generate_episodes(pm, "medium", 1, seed=4)[0]
    # An obstacle across the corridor 1 m ahead of the start, along the geodesic.
    pts = shortest_path_points(pm, (ep.start_x, ep.start_y), ep.goal)
    (x0, y0), (x1, y1) = pts[0], pts[1]
    d = math.dist(pts[0], pts[1])
    ox, oy = x0 + (x1 - x0) * 1.0 / d, y0 + (y1 - y0) * 1.0 / d
    fields = goal_fields(world, pm, ep.goal)  # planned on the building without the obstacle
    body = world.add_obstacle(ox, oy, 2.6)
    base = _base(world)
    try:
        r = run_oracle(base, pm, ep, fields=fields)
    finally:
        base.close()
        world.remove_obstacle(body)
    assert not r.success and r.collisions >= 1
    assert r.failure_reason.startswith("blocked")
