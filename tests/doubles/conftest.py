"""Fixtures for behaviour and tree tests on the seams' test doubles (no pybullet).

``rig(building, pose, **doubles)``: a FakeBase on a FakeClock, a ScriptedGrounder over the
building's priori-map, a FakeCoarseDirection, a FakeRefiner and a FakePlanner (the real
graph planner), wired into a Context by the runner's ``make_context``, plus a blackboard
client that may write every ``/pmnav`` key. ``rig.run(b)`` ticks like the runner does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import py_trees
import pytest
from blackboard_kit import BlackboardAccess, cleared, writer
from py_trees.common import Status

from pmnav_bt.backends import Backends
from pmnav_bt.behaviours.context import Context
from pmnav_bt.config import load_config
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import (
    FakeBase,
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.runner import make_context

PERIOD = 0.1


@dataclass
class DoubleRig(BlackboardAccess):
    base: FakeBase
    pm: PrioriMap
    ctx: Context
    bb: py_trees.blackboard.Client
    grounder: ScriptedGrounder
    coarse: FakeCoarseDirection
    refiner: FakeRefiner
    planner: FakePlanner
    seen: list[Status] = field(default_factory=list)

    def run(self, b: py_trees.behaviour.Behaviour, max_ticks: int = 2000) -> list[Status]:
        """Tick ``b`` until it ends: the status after each tick (the runner's loop)."""
        seen = []
        for _ in range(max_ticks):
            b.tick_once()
            seen.append(b.status)
            if b.status != Status.RUNNING:
                break
            self.ctx.worker.drain()
            self.base.clock.wait(PERIOD)
        return seen


_MAPS: dict[str, PrioriMap] = {}


def priori_map(name: str) -> PrioriMap:
    if name not in _MAPS:
        _MAPS[name] = parse_building(load_building(name))
    return _MAPS[name]


@pytest.fixture(autouse=True)
def clean_blackboard():
    yield from cleared()


@pytest.fixture
def rig():
    made: list[DoubleRig] = []

    def make(
        building: str,
        pose: Pose2D,
        *,
        overrides: tuple[str, ...] = (),
        grounder: ScriptedGrounder | None = None,
        coarse: FakeCoarseDirection | None = None,
        refiner: FakeRefiner | None = None,
        planner: FakePlanner | None = None,
        deferred: bool = True,
    ) -> DoubleRig:
        pm = priori_map(building)
        base = FakeBase(pose)
        backends = Backends(
            grounder=grounder or ScriptedGrounder(pm),
            coarse=coarse or FakeCoarseDirection(),
            refiner=refiner or FakeRefiner(),
            planner=planner or FakePlanner(),
        )
        cfg = load_config(overrides=[ORACLE, *overrides])
        ctx = make_context(base, pm, cfg, deferred_work=deferred, backends=backends)
        bb = writer()
        r = DoubleRig(
            base,
            pm,
            ctx,
            bb,
            *(getattr(backends, k) for k in ("grounder", "coarse", "refiner", "planner")),
        )
        made.append(r)
        return r

    yield make
    for r in made:
        r.ctx.worker.shutdown()


@pytest.fixture
def office() -> PrioriMap:
    """The straight_office priori-map (one corridor along y = 0, from x = 0 to 54)."""
    return priori_map("straight_office")
