"""Fixtures for the behaviour tests: the real simulator, a Context, and a tick loop.

Each test gets a ``rig``: a fresh SimBase (own SimClock, 160x120 camera) in a
module-scoped fig2_hospital world, a Context from the runner's ``make_context`` (real
ground-truth grounder, refiner, planner and worker), and a blackboard client that may
write any ``/pmnav`` key to put a behaviour in a known situation. ``rig.run`` is the
runner's loop: tick, then let the worker finish and 0.1 s of sim time pass.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field

import py_trees
import pytest
from blackboard_kit import BlackboardAccess, cleared, writer
from py_trees.common import Status

from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.config import load_config
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.seams import MotionStatus, Pose2D
from pmnav_bt.sim.odometry import NoisyOdometry
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.world import SimWorld
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.runner import make_context

PERIOD = 0.1  # seconds of sim time between ticks (the runner's 10 Hz)
PARK = Pose2D(-500.0, -500.0, 0.0)  # where a finished test's body is left, out of every view


@dataclass
class Rig(BlackboardAccess):
    """One behaviour under test, against the real simulator."""

    world: SimWorld
    body: SimBase  # the simulated body: its pose is the ground truth
    base: object  # what the behaviours drive: ``body`` or NoisyOdometry around it
    ctx: Context
    pm: PrioriMap
    bb: py_trees.blackboard.Client
    obstacles: list[int] = field(default_factory=list)

    # -- blackboard -------------------------------------------------------------------------

    # -- time -------------------------------------------------------------------------------

    def tick(self, b: py_trees.behaviour.Behaviour) -> Status:
        b.tick_once()
        return b.status

    def wait(self, dt: float = PERIOD) -> None:
        """What the runner does between ticks: let the worker finish, let sim time pass."""
        self.ctx.worker.drain()
        self.base.clock.wait(dt)

    def run(
        self,
        b: py_trees.behaviour.Behaviour,
        max_ticks: int = 1000,
        until: Callable[[], bool] | None = None,
    ) -> list[Status]:
        """Tick ``b`` until it ends (or ``until()`` holds); the status after each tick."""
        seen = []
        for _ in range(max_ticks):
            seen.append(self.tick(b))
            if seen[-1] != Status.RUNNING or (until is not None and until()):
                return seen
            self.wait()
        return seen

    def hold_worker(self) -> threading.Event:
        """Occupy the (one-thread) worker until the returned event is set, so that a job a
        behaviour submits stays queued: its first tick is then RUNNING for certain."""
        release = threading.Event()
        self.ctx.worker.submit(lambda c: release.wait(10.0))
        return release

    # -- the body ---------------------------------------------------------------------------

    def true_pose(self) -> Pose2D:
        return self.body.pose()

    def estimate(self) -> Pose2D:
        """The tree's map pose: map_T_odom composed with the odometry pose."""
        return map_pose(self.get("map_T_odom"), self.ctx.base.pose())

    def stopped(self) -> bool:
        """No velocity command in force and no motion going on."""
        return (
            self.body.velocity_command == (0.0, 0.0)
            and self.body.motion_status() == MotionStatus.IDLE
        )

    def add_obstacle(self, x: float, y: float, size: float = 0.6, height: float = 1.0) -> int:
        """A box in the world for this test only (removed afterwards)."""
        body = self.world.add_obstacle(x, y, size, height)
        self.obstacles.append(body)
        return body

    @staticmethod
    def expect(seen: list[Status], final: Status) -> None:
        """RUNNING on every tick but the last, which is ``final``."""
        assert seen, "never ticked"
        assert seen[-1] == final, f"ended {seen[-1]} after {len(seen)} ticks"
        assert all(s == Status.RUNNING for s in seen[:-1]), seen

    @staticmethod
    def yaw_error(a: float, b: float) -> float:
        return abs(wrap_angle(a - b))

    def plan(self, start: str, goal: str):
        """A plan from the real graph planner (for targets and plans on the blackboard)."""
        return self.ctx.planner.plan(self.pm, start, goal)


@pytest.fixture(scope="module")
def world():
    w = SimWorld("fig2_hospital")
    yield w
    w.close()


@pytest.fixture(scope="module")
def pm(world):
    return parse_building(world.building)


@pytest.fixture(autouse=True)
def clean_blackboard():
    yield from cleared()


@pytest.fixture
def make_rig(world, pm, clean_blackboard):
    """``make_rig(pose, width=160, height=120, noise=None, seed=0, budget=None,
    overrides=(), segmentation=True)`` -> Rig; everything is torn down after the test."""
    made: list[Rig] = []

    def make(
        pose: Pose2D,
        *,
        width: int = 160,
        height: int = 120,
        noise: float | None = None,
        seed: int = 0,
        budget: int | None = None,
        overrides: tuple[str, ...] = (),
        segmentation: bool = True,
    ) -> Rig:
        body = SimBase(world, pose=pose, width=width, height=height, segmentation=segmentation)
        base = body if noise is None else NoisyOdometry(body, noise, seed=seed)
        ctx = make_context(base, pm, load_config(overrides=[ORACLE, *overrides]), seed, budget)
        bb = writer()
        rig = Rig(world, body, base, ctx, pm, bb)
        made.append(rig)
        return rig

    yield make
    for rig in made:
        rig.ctx.worker.shutdown()
        for ob in rig.obstacles:
            world.remove_obstacle(ob)
        rig.body.set_pose(PARK)
        rig.body.close()
