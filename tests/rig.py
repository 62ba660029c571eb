"""The one tick rig of the behaviour and tree tests: a Context on a body chosen by name.

``Rig`` holds one Context built by the runner's ``make_context`` on one of two bodies:

- ``"doubles"``: the seams' test doubles (``pmnav_bt.testing.doubles``): a kinematic
  FakeBase on a FakeClock, a ScriptedGrounder that sees what the priori-map puts in view,
  FakeCoarseDirection, FakeRefiner and FakePlanner (the real graph planner). No simulator:
  the body for behaviour logic (what a leaf decides, writes and reports, tick by tick).
- ``"pybullet"``: a SimBase in a SimWorld with the back ends the config names (the
  ground-truth grounder, ...), optionally behind drifting odometry: the body for what needs
  geometry (depth, walls, distances, what a camera really sees).

The ``make_rig`` fixture (tests/conftest.py) picks the body from the ``body`` fixture. A leaf
or subtree is ticked the way ``trees.runner.run_tree`` ticks a whole tree: tick, then let
the worker finish its jobs and one tick period pass on the body's clock (``run``,
``ticks``); a whole tree goes through ``run_tree`` itself (``mission``).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import py_trees
from blackboard_kit import BlackboardAccess, writer
from py_trees.common import Status

from pmnav_bt.backends import Backends
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.config import load_config
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.seams import CameraIntrinsics, MotionStatus, Pose2D
from pmnav_bt.testing.doubles import (
    FakeBase,
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.trees.runner import RunOutcome, make_context, run_tree

BODIES = ("doubles", "pybullet")
PERIOD = 0.1  # seconds of clock time between ticks (the runner's 10 Hz)
PARK = Pose2D(-500.0, -500.0, 0.0)  # where a finished test's simulated body is left
DOUBLES_HFOV = math.radians(60.0)  # the FakeBase camera's field of view


@dataclass
class Rig(BlackboardAccess):
    """One behaviour, subtree or tree under test, on one body."""

    body: object  # the body itself: its pose is the ground truth (FakeBase or SimBase)
    base: object  # what the behaviours drive: ``body``, or NoisyOdometry around it
    ctx: Context
    pm: PrioriMap
    bb: py_trees.blackboard.Client
    world: object | None = None  # the SimWorld of a pybullet body
    obstacles: list[int] = field(default_factory=list)

    # -- time -------------------------------------------------------------------------------

    def tick(self, b: py_trees.behaviour.Behaviour) -> Status:
        b.tick_once()
        return b.status

    def wait(self, dt: float = PERIOD) -> None:
        """What the runner does between ticks: let the worker finish, let clock time pass."""
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

    def ticks(self, b: py_trees.behaviour.Behaviour, expected: Sequence[Status]) -> None:
        """Tick ``b`` once per entry of ``expected`` (waiting a period after each) and assert
        the status after every tick."""
        seen = []
        for _ in expected:
            seen.append(self.tick(b))
            self.wait()
        assert seen == list(expected)

    def mission(self, goal: str, **run) -> RunOutcome:
        """The whole tree of the context's variant for ``goal``, as the runner runs it
        (``trees.runner.run_tree``; ``run``: its keyword arguments)."""
        return run_tree(self.ctx, goal, **run)

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
        """A box in the world for this test only (removed afterwards; pybullet only)."""
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
        """A plan from the context's planner (for targets and plans on the blackboard)."""
        return self.ctx.planner.plan(self.pm, start, goal)

    def close(self) -> None:
        """Stop the worker; a simulated body leaves the world as it found it."""
        self.ctx.worker.shutdown()
        if self.world is not None:
            for ob in self.obstacles:
                self.world.remove_obstacle(ob)
            self.body.set_pose(PARK)
            self.body.close()


def build_rig(
    body: str,
    pm: PrioriMap,
    pose: Pose2D,
    *,
    world=None,
    width: int = 160,
    height: int = 120,
    seed: int = 0,
    budget: int | None = None,
    overrides: tuple[str, ...] = (),
    noise: float | None = None,
    segmentation: bool = True,
    reading_width: int = 0,
    grounder: ScriptedGrounder | None = None,
    coarse: FakeCoarseDirection | None = None,
    refiner: FakeRefiner | None = None,
    planner: FakePlanner | None = None,
) -> Rig:
    """A Rig at ``pose`` on ``body`` (one of BODIES), with the config (ORACLE + ``overrides``)
    and a ``width`` x ``height`` camera.

    ``"doubles"``: any double not given (``grounder``, ``coarse``, ``refiner``, ``planner``)
    is a default one; background jobs start between ticks, as in simulation.
    ``"pybullet"``: a SimBase in ``world`` with the config's back ends; background jobs start
    at once, in the worker's thread. ``noise``: drifting odometry (NoisyOdometry) around the
    body; ``segmentation``: the camera's labels (the ground-truth grounder needs them);
    ``reading_width``: a wider view for reading signs (``Observation.reading``; 0: none).
    """
    cfg = load_config(overrides=[ORACLE, *overrides])
    doubles = (grounder, coarse, refiner, planner)
    if body == "pybullet":
        from pmnav_bt.sim.odometry import NoisyOdometry
        from pmnav_bt.sim.robot import SimBase

        assert all(d is None for d in doubles), "test doubles need the doubles body"
        sim = SimBase(
            world,
            pose=pose,
            width=width,
            height=height,
            segmentation=segmentation,
            reading_width=reading_width,
        )
        base = sim if noise is None else NoisyOdometry(sim, noise, seed=seed)
        return Rig(sim, base, make_context(base, pm, cfg, seed, budget), pm, writer(), world)
    assert body == "doubles", f"no body {body!r}; choose from {BODIES}"
    assert noise is None and segmentation and not reading_width, "these need pybullet"
    fake = FakeBase(pose, intrinsics=CameraIntrinsics.from_hfov(width, height, DOUBLES_HFOV))
    backends = Backends(
        grounder=grounder or ScriptedGrounder(pm),
        coarse=coarse or FakeCoarseDirection(),
        refiner=refiner or FakeRefiner(),
        planner=planner or FakePlanner(),
    )
    ctx = make_context(fake, pm, cfg, seed, budget, deferred_work=True, backends=backends)
    return Rig(fake, fake, ctx, pm, writer())
