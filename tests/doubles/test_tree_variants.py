"""Every registered tree variant, built by name on the seams' test doubles and ticked with
a box in the way: its context gives it only what it may read, its drives go round the box
(the detour path runs) and the run never ends in INTERNAL_ERROR (the map-less baseline
once read the priori-map there)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmnav_bt.config import load_config
from pmnav_bt.failures import FailureCode
from pmnav_bt.registry import Backends
from pmnav_bt.seams import Observation, Pose2D
from pmnav_bt.testing.doubles import (
    FakeBase,
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.runner import make_context, run_tree
from pmnav_bt.trees.variants import TREE_VARIANTS

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
GOAL = "room2"  # its door (10, 1.1) is in view from the start


@dataclasses.dataclass
class BoxAhead(FakeBase):
    """A FakeBase whose frames taken while it drives forward have depth: the floor and,
    straight ahead at ``box_m``, a thin box (``half_width`` m either side of the optical
    axis) that moves with the camera, so that every drive finds its way blocked with open
    floor beside it. Frames taken standing have no depth (as FakeBase's)."""

    box_m: float = 1.0
    half_width: float = 0.08

    def observe(self) -> Observation:
        obs = super().observe()
        if self.velocity_command[0] == 0.0:
            return obs
        k, h = obs.intrinsics, obs.camera_height
        rows = np.arange(k.height, dtype=float)[:, None]
        below = rows > k.cy
        floor = np.where(below, h * k.fy / np.maximum(rows - k.cy, 1e-6), 8.0)
        depth = np.broadcast_to(floor, (k.height, k.width)).astype(np.float32).copy()
        lateral = np.abs((k.cx - np.arange(k.width)) * self.box_m / k.fx)
        depth[:, lateral <= self.half_width] = self.box_m
        return dataclasses.replace(obs, depth=depth)


def ticked(variant: str, office):
    base = BoxAhead(START)
    backends = Backends(
        ScriptedGrounder(office), FakeCoarseDirection(), FakeRefiner(), FakePlanner()
    )
    cfg = load_config(overrides=[ORACLE, f"tree.variant={variant}", "tree.replans=0"])
    ctx = make_context(base, office, cfg, budget=80, deferred_work=True, backends=backends)
    return run_tree(ctx, GOAL, max_ticks=4000), ctx


@pytest.mark.parametrize("variant", TREE_VARIANTS.names())
def test_each_variant_goes_round_a_box_without_an_internal_error(variant, office):
    out, ctx = ticked(variant, office)
    assert out.success or out.failure.code != FailureCode.INTERNAL_ERROR, out.failure
    detours = [e for e in ctx.trace if e.kind == "detour"]
    assert detours, [e.kind for e in ctx.trace]
    if TREE_VARIANTS.spec(variant).knows.plans:  # PM-Nav: only inside the map's corridors
        for d in detours:
            loc = office.locate(d.data["x"], d.data["y"])
            assert loc.offset <= loc.segment.width / 2.0 - 0.3


def test_the_map_less_context_holds_the_sign_vocabulary_and_no_map_check(office):
    base = FakeBase(START)
    cfg = load_config(overrides=[ORACLE, "tree.variant=mapless"])
    backends = Backends(
        ScriptedGrounder(office), FakeCoarseDirection(), FakeRefiner(), FakePlanner()
    )
    ctx = make_context(base, office, cfg, backends=backends)
    try:
        assert ctx.planner is None and ctx.detour_check is None
        assert ctx.pm is not office and ctx.pm.building.waypoints == ()
    finally:
        ctx.worker.shutdown()
    ctx = make_context(FakeBase(START), office, load_config(overrides=[ORACLE]), backends=backends)
    try:
        assert ctx.pm is office and ctx.planner is backends.planner
        # the map's check: 0.5 m off the centre line of the 2.2 m corridor is 0.6 m from a wall
        assert ctx.detour_check((6.0, 0.5), 0.3) and not ctx.detour_check((6.0, 1.0), 0.3)
    finally:
        ctx.worker.shutdown()
