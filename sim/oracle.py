"""The oracle agent: follows the geodesic with the ground-truth pose; the ceiling for SR/SPL.

The geodesic is SPL's shortest path: through the free space, less the robot's radius
and the landmarks' footprints, to the success disc (:func:`goal_geodesic`).

Discrete actions as the agents use them: turn 30 deg until the next polyline point is
within +-15 deg, then 0.25 m steps. Two fine moves keep the track exact, since 30 deg
turns and 0.25 m steps cannot land on arbitrary headings and distances: a velocity
turn removes the remaining heading error, and a velocity drive covers the last
fraction of a step to each point. Each fine move counts as one action. Nothing is
rendered, so a run costs only the body's kinematics.

Run ``python -m pmnav_bt.sim.oracle`` for scores on every built-in building.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from pathlib import Path

from pmnav_bt.eval.geodesic import GeodesicField
from pmnav_bt.eval.metrics import EpisodeResult, aggregate_by_tier
from pmnav_bt.eval.task import SUCCESS_RADIUS_M
from pmnav_bt.geometry import heading, wrap_angle
from pmnav_bt.map.building import Building
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.seams import CREATE3_RADIUS_M, FORWARD_STEP_M, DiscreteAction, MotionStatus
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.episodes import (
    TIERS,
    Episode,
    EpisodeGenerationError,
    generate_episodes,
    goal_door_in_world,
    goal_geodesic,
    score_episode,
)
from pmnav_bt.sim.robot import COLLISION_HEIGHT, SimBase
from pmnav_bt.sim.world import SimWorld

ALIGN_TOL = math.radians(15.0)  # coarse: turn in 30 deg steps until within this
FINE_TOL = math.radians(0.2)  # fine: velocity turn until within this
REACH_TOL = 0.01  # metres: a polyline point counts as reached
ORACLE_TICK = 0.05  # s; coarser than the default clock tick, for speed (motion is kinematic)
MAX_BLOCKED = 3  # give up after this many blocked motions
CLEARANCE_M = 0.05  # the oracle's path keeps this far beyond the body's radius from walls


class _Runner:
    """Drives a SimBase through discrete and fine moves, counting actions and distance."""

    def __init__(self, base: SimBase, budget: int, trace: bool):
        self.base = base
        self.budget = budget
        self.actions = 0
        self.blocked = 0
        self.travelled = 0.0
        self.trace: list[tuple[float, float, float]] | None = [] if trace else None
        self._last = base.pose()
        self._record()

    def _record(self) -> None:
        q = self.base.pose()
        self.travelled += math.hypot(q.x - self._last.x, q.y - self._last.y)
        self._last = q
        if self.trace is not None:
            self.trace.append((round(q.x, 4), round(q.y, 4), round(q.yaw, 5)))

    def _settle(self, timeout: float) -> None:
        clock = self.base.clock
        t_end = clock.now() + timeout
        while self.base.motion_status() == MotionStatus.MOVING and clock.now() < t_end:
            clock.wait(ORACLE_TICK)
        if self.base.motion_status() == MotionStatus.MOVING:
            self.base.stop()
        if self.base.motion_status() == MotionStatus.BLOCKED:
            self.blocked += 1
        self.actions += 1
        self._record()

    def step(self, action: DiscreteAction) -> None:
        self.base.step(action)
        self._settle(30.0)

    def fine_turn(self, angle: float) -> None:
        w = self.base.max_angular
        self._velocity(0.0, math.copysign(w, angle), abs(angle) / w)

    def fine_forward(self, dist: float) -> None:
        v = self.base.max_linear
        self._velocity(v, 0.0, dist / v)

    def _velocity(self, v: float, w: float, duration: float) -> None:
        # Whole ticks at full speed, then one tick at the speed that lands exactly.
        clock = self.base.clock
        n = int(duration / ORACLE_TICK)
        rest = duration - n * ORACLE_TICK
        self.base.set_velocity(v, w)
        for _ in range(n):
            clock.wait(ORACLE_TICK)
            if self.base.motion_status() != MotionStatus.MOVING:
                break
        if rest > 1e-9 and self.base.motion_status() == MotionStatus.MOVING:
            k = rest / ORACLE_TICK
            self.base.set_velocity(v * k, w * k)
            clock.wait(ORACLE_TICK)
        blocked = self.base.motion_status() == MotionStatus.BLOCKED
        self.base.stop()
        self.blocked += blocked
        self.actions += 1
        self._record()

    @property
    def exhausted(self) -> bool:
        return self.actions >= self.budget or self.blocked >= MAX_BLOCKED


def follow(runner: _Runner, points: Sequence[tuple[float, float]]) -> None:
    """Follow a polyline point by point (the first point is where the body is)."""
    for target in points[1:]:
        while not runner.exhausted:
            q = runner.base.pose()
            dist = math.hypot(target[0] - q.x, target[1] - q.y)
            if dist <= REACH_TOL:
                break
            err = wrap_angle(heading((q.x, q.y), target) - q.yaw)
            if abs(err) > ALIGN_TOL:
                runner.step(DiscreteAction.TURN_LEFT if err > 0 else DiscreteAction.TURN_RIGHT)
            elif abs(err) > FINE_TOL:
                runner.fine_turn(err)
            elif dist >= FORWARD_STEP_M:
                runner.step(DiscreteAction.FORWARD)
            else:
                runner.fine_forward(dist)


def run_oracle(
    base: SimBase,
    pm: PrioriMap,
    episode: Episode,
    trace: bool = False,
    fields: tuple[GeodesicField, GeodesicField] | None = None,
) -> EpisodeResult:
    """Place the body at the episode's start, follow the geodesic, stop; score the run.

    ``fields``: the goal's (scoring, driving) distance fields, if already computed for
    this world (see :func:`goal_fields`).
    """
    t0 = time.perf_counter()
    score, drive = fields or goal_fields(base.world, pm, episode.goal)
    base.set_pose(episode.start_pose)
    collisions0, contacts0 = base.stats.collisions, base.world.people.contacts
    runner = _Runner(base, episode.step_budget, trace)
    follow(runner, drive.path((episode.start_x, episode.start_y)))
    base.stop()
    q = base.pose()
    reason = None
    if runner.blocked >= MAX_BLOCKED:
        reason = f"blocked {runner.blocked} times near ({q.x:.2f}, {q.y:.2f})"
    elif runner.exhausted:
        reason = f"step budget of {runner.budget} actions exhausted"
    return score_episode(
        pm,
        episode,
        (q.x, q.y),
        geodesic=score,
        path_length=runner.travelled,
        steps=runner.actions,
        collisions=base.stats.collisions - collisions0,
        people_contacts=base.world.people.contacts - contacts0,
        wall_time=time.perf_counter() - t0,
        failure=reason,
        trace=runner.trace,
        door=goal_door_in_world(base.world, pm, episode.goal),
    )


def goal_fields(world: SimWorld, pm: PrioriMap, goal: str) -> tuple[GeodesicField, GeodesicField]:
    """The goal's distance fields: for scoring (the body's radius) and for driving (with
    ``CLEARANCE_M`` more, so that the body does not graze corners, and ending
    ``CLEARANCE_M`` inside the success disc)."""
    footprints = world.obstacle_footprints(COLLISION_HEIGHT)
    floor = world.floor_space()
    door = goal_door_in_world(world, pm, goal)
    score = goal_geodesic(pm, goal, footprints, floor=floor, door=door)
    drive = goal_geodesic(
        pm,
        goal,
        footprints,
        floor=floor,
        robot_radius=CREATE3_RADIUS_M + CLEARANCE_M,
        radius=SUCCESS_RADIUS_M - CLEARANCE_M,
        door=door,
    )
    return score, drive


def evaluate_oracle(
    building: Building | str | Path, episodes: Sequence[Episode], trace: bool = False
) -> list[EpisodeResult]:
    """Run the oracle on episodes of one building (one world, no rendering)."""
    b = building if isinstance(building, Building) else load_building(building)
    pm = parse_building(b)
    with SimWorld(b, ceiling=False) as world:
        base = SimBase(
            world, SimClock(tick=ORACLE_TICK), width=16, height=12, depth=False, segmentation=False
        )
        fields: dict[str, tuple[GeodesicField, GeodesicField]] = {}
        try:
            out = []
            for ep in episodes:
                if ep.goal not in fields:
                    fields[ep.goal] = goal_fields(world, pm, ep.goal)
                out.append(run_oracle(base, pm, ep, trace, fields[ep.goal]))
            return out
        finally:
            base.close()


def main(argv: Sequence[str] | None = None) -> None:
    """Oracle SR/SPL per tier on built-in buildings: ``python -m pmnav_bt.sim.oracle``."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("buildings", nargs="*", help="building files or built-in names (default: all)")
    ap.add_argument("-n", type=int, default=20, help="episodes per tier and building")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    for name in args.buildings or builtin_buildings():
        b = load_building(name)
        episodes: list[Episode] = []
        for tier in TIERS:
            try:
                episodes += generate_episodes(b, tier, args.n, seed=args.seed)
            except EpisodeGenerationError as err:
                print(f"({err})")
        results = evaluate_oracle(b, episodes)
        print(f"## {b.name}: oracle, {args.n} episodes per tier, seed {args.seed}")
        print(aggregate_by_tier(results).to_markdown())
        for r in results:
            if not r.success:
                print(f"- {r.episode_id}: {r.failure_reason}")


if __name__ == "__main__":
    main()
