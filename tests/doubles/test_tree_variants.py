"""Every registered tree variant, built by name on the seams' test doubles and ticked with
a box in the way: its context gives it only what it may read, its drives go round the box
(the detour path runs) and the run never ends in INTERNAL_ERROR (the map-less baseline
once read the priori-map there)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmnav_bt.backends import Backends
from pmnav_bt.config import load_config
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import Observation, Pose2D
from pmnav_bt.testing import doubles
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.tree_variants import TREE_VARIANTS
from pmnav_bt.trees.runner import make_context, run_tree


@pytest.fixture(scope="module")
def office():
    return parse_building(load_building("straight_office"))


START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
GOAL = "room2"  # its door (10, 1.1) is in view from the start


@dataclasses.dataclass
class BoxAhead(doubles.FakeBase):
    """A FakeBase whose frames taken while it drives forward, or stands held up in a
    drive, have depth: the floor and, straight ahead at ``box_m``, a thin box
    (``half_width`` m either side of the optical axis) that moves with the camera, so
    that every drive finds its way blocked with open floor beside it. Frames taken
    standing otherwise have no depth (as doubles.FakeBase's)."""

    box_m: float = 1.0
    half_width: float = 0.08
    held: bool = False  # the last drive frame showed the box (it stopped for it)

    def set_velocity(self, linear: float, angular: float) -> None:
        super().set_velocity(linear, angular)
        self.held = self.held and linear == 0.0 and angular == 0.0

    def stop(self) -> None:
        self.held = self.held or self.velocity_command[0] != 0.0
        super().stop()

    def observe(self) -> Observation:
        obs = super().observe()
        if self.velocity_command[0] == 0.0 and not self.held:
            return obs
        k, h = obs.intrinsics, obs.camera_height
        rows = np.arange(k.height, dtype=float)[:, None]
        below = rows > k.cy
        floor = np.where(below, h * k.fy / np.maximum(rows - k.cy, 1e-6), 8.0)
        depth = np.broadcast_to(floor, (k.height, k.width)).astype(np.float32).copy()
        lateral = np.abs((k.cx - np.arange(k.width)) * self.box_m / k.fx)
        depth[:, lateral <= self.half_width] = self.box_m
        return dataclasses.replace(obs, depth=depth)


def on_doubles(office, variant: str, base=None, **kw):
    """``variant``'s context (``make_context``) on the doubles over ``office``."""
    backends = Backends(
        doubles.ScriptedGrounder(office),
        doubles.FakeCoarseDirection(),
        doubles.FakeRefiner(),
        doubles.FakePlanner(),
    )
    cfg = load_config(overrides=[ORACLE, f"tree.variant={variant}", "tree.replans=0"])
    return make_context(base or doubles.FakeBase(START), office, cfg, backends=backends, **kw)


def ticked(variant: str, office):
    ctx = on_doubles(office, variant, BoxAhead(START), budget=80, deferred_work=True)
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
    ctx = on_doubles(office, "mapless")
    ctx.worker.shutdown()
    assert ctx.planner is None and ctx.detour_check is None
    assert ctx.pm is not office and ctx.pm.building.waypoints == ()
    ctx = on_doubles(office, "pmnav")
    ctx.worker.shutdown()
    assert ctx.pm is office and ctx.planner is not None
    # the map's check: 0.5 m off the centre line of the 2.2 m corridor is 0.6 m from a wall
    assert ctx.detour_check((6.0, 0.5), 0.3) and not ctx.detour_check((6.0, 1.0), 0.3)
