"""Tick a PM-Nav tree against any Base until it ends, logging a snapshot per tick.

The runner owns time: after each tick it lets one tick period pass on the base's
Clock (the simulator advances physics; the robot sleeps). In simulation it first
waits for the worker's jobs, so that the same seed gives the same episode whatever
the machine's speed; on the robot it never waits.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, TextIO

import py_trees

from pmnav_bt.backends import Backends, build_backends
from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.config import Config
from pmnav_bt.eval.task import action_budget as task_action_budget
from pmnav_bt.failures import Failure, FailureCode, failure_from, root_cause
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.planning.resolve import step_entity
from pmnav_bt.pose.evidence.floor_model import wall_source
from pmnav_bt.seams import Base, Entity
from pmnav_bt.tree_variants import TREE_VARIANTS
from pmnav_bt.trees.map_watch import watch_misreads
from pmnav_bt.trees.snapshots import SnapshotLogger
from pmnav_bt.trees.view_record import ViewRecorder

if TYPE_CHECKING:
    from pmnav_bt.map.floorplan import FloorPlanImage


@dataclass(frozen=True)
class TickTime:
    """What one tick took, in seconds: ``wall`` on the clock, ``cpu`` of the ticking
    thread's own CPU time (``time.thread_time``), which other processes' load and the
    worker's threads do not inflate: what the tree's code costs."""

    wall: float
    cpu: float


@dataclass
class RunOutcome:
    """How a run ended."""

    success: bool
    failure: Failure | None
    ticks: int
    clock_time: float
    fix_attempts: int
    replans: int
    actions: int

    @property
    def cause(self) -> Failure | None:
        """The root-cause failure when recoveries failed after it, else None."""
        root = root_cause(self.failure)
        return root if root is not self.failure else None


def action_budget(config: Config, route_m: float | None) -> int:
    """The config's action budget for a corridor route of ``route_m`` metres
    (:func:`pmnav_bt.eval.task.action_budget`)."""
    return task_action_budget(route_m, config.tree.budget_actions, config.tree.budget_path_factor)


def variant_backends(config: Config, pm: PrioriMap, *, on_robot: bool, seed: int = 0) -> Backends:
    """The back ends the config names, built on what the tree variant ``config.tree.variant``
    may read of ``pm`` (a planner only for a variant that plans); an unknown variant is
    refused here, in one line. A long-lived node builds them once with this."""
    knows = TREE_VARIANTS.spec(config.tree.variant).knows
    return build_backends(
        config, knows.known(pm), on_robot=on_robot, seed=seed, planner=knows.plans
    )


def make_context(
    base: Base,
    pm: PrioriMap,
    config: Config,
    seed: int = 0,
    budget: int | None = None,
    deferred_work: bool = False,
    *,
    on_robot: bool = False,
    backends: Backends | None = None,
    grid: FloorPlanImage | None = None,
) -> Context:
    """The Context of the tree variant ``config.tree.variant`` (``pmnav_bt.tree_variants``): what
    it may read of ``pm`` (the whole priori-map, or the sign vocabulary only), the back
    ends the config names built on that (``build_backends``; a planner only for a variant
    that plans), and its drives' detour check, wired together.

    ``deferred_work``: background jobs start between ticks (simulation; see Worker).
    ``on_robot``: the observations carry no simulator labels (back ends that need them are
    refused). ``backends``: ready-made back ends instead (tests, test doubles); a variant
    that plans nothing drops their planner. ``grid``: the building's occupancy grid (its
    ``floor_plan.ros_map``; None: it has none), for the localization's wall model
    (``tree.localization_walls``, ``pose.evidence.floor_model.wall_source``).
    """
    knows = TREE_VARIANTS.spec(config.tree.variant).knows
    known = knows.known(pm)
    if backends is None:
        backends = build_backends(config, known, on_robot=on_robot, seed=seed, planner=knows.plans)
    elif not knows.plans:
        backends = replace(backends, planner=None)
    ctx = Context.wired(
        base, known, config, backends, budget, deferred_work,
        detour_check=knows.detour_check(known),
        walls=wall_source(config.tree.localization_walls, grid),
    )  # fmt: skip
    watch_misreads(ctx)
    return ctx


def build_tree(ctx: Context, goal: str) -> py_trees.trees.BehaviourTree:
    """The tree of the variant ``ctx.config.tree.variant`` for ``goal``
    (``pmnav_bt.tree_variants.TREE_VARIANTS``), on a context ``make_context`` built for it."""
    return TREE_VARIANTS.spec(ctx.config.tree.variant).build_tree(ctx, goal)


def _target_entity(ctx: Context) -> Entity | None:
    """What the tree looked for when it ended (the plan step's room or landmark)."""
    t = _blackboard("target")
    return None if t is None or t.look_for is None else step_entity(ctx.pm.building, t.look_for)


def _blackboard(key: str):
    store = py_trees.blackboard.Blackboard.storage
    return store.get(f"{NAMESPACE}/{key}")


def run_tree(
    ctx: Context,
    goal: str,
    max_ticks: int = 100_000,
    log: TextIO | None = None,
    on_tick: Callable[[py_trees.trees.BehaviourTree], None] | None = None,
    sync_workers: bool = True,
    tick_times: list[TickTime] | None = None,
    view: ViewRecorder | None = None,
    build: Callable[[Context, str], py_trees.trees.BehaviourTree] | None = None,
    ended_on: Callable[[], Context] | None = None,
) -> RunOutcome:
    """Build the tree for ``goal`` and tick it until it succeeds or fails.

    ``build``: how to build it (default ``build_tree``, the config's tree variant; the
    mission across levels: ``trees.site.build_site_tree``), after the blackboard is cleared;
    ``ended_on``: the context of the level the run ended on, whose map explains a failure
    (default ``ctx``).

    ``tick_times`` (optional) collects what every tick took (wall and CPU time).
    ``log``: write the tree log here, each tick's ``view`` entry made by ``view`` (default
    a ViewRecorder that knows the building by the map's name and no true pose).
    """
    py_trees.blackboard.Blackboard.clear()
    if log is not None and view is None:
        view = ViewRecorder(ctx)
    tree = (build or build_tree)(ctx, goal)
    if log is not None:
        tree.add_post_tick_handler(SnapshotLogger(tree, log, ctx.now, view=view, goal=goal))
    period = 1.0 / ctx.config.tree.tick_hz
    status = py_trees.common.Status.RUNNING
    crash: Failure | None = None
    try:
        tree.setup()
        while tree.count < max_ticks:
            t0, c0 = time.perf_counter(), time.thread_time()
            try:
                tree.tick()
            except Exception as err:  # noqa: BLE001 - a bug in a leaf ends the run, reported
                crash = failure_from(err, "tick")
                status = py_trees.common.Status.FAILURE
                break
            if tick_times is not None:
                tick_times.append(TickTime(time.perf_counter() - t0, time.thread_time() - c0))
            if on_tick is not None:
                on_tick(tree)  # outside the guard: a handler may end the run (cancel)
            status = tree.root.status
            if status != py_trees.common.Status.RUNNING:
                break
            if sync_workers:
                ctx.worker.drain()
            ctx.base.clock.wait(period)
    finally:
        ctx.base.stop()
        tree.interrupt()
        ctx.worker.shutdown()
    failure = None
    if status != py_trees.common.Status.SUCCESS:
        failure = (
            crash
            or _blackboard("failure")
            or Failure(FailureCode.TIMEOUT, f"no result after {tree.count} ticks")
        )
        end = ended_on() if ended_on is not None else ctx
        if end.misreads is not None:  # what was read where the target was not found
            failure = end.misreads.explain(failure, _target_entity(end))
    return RunOutcome(
        success=status == py_trees.common.Status.SUCCESS,
        failure=failure,
        ticks=tree.count,
        clock_time=ctx.now(),
        fix_attempts=_blackboard("fix_attempts") or 0,
        replans=_blackboard("replans") or 0,
        actions=ctx.odometer.actions,
    )
