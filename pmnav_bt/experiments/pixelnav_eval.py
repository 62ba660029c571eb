"""The skill on its own: reach a goal pixel 1-5 m away, on held-out generated buildings.

Goals are drawn the way training draws them (``data.Roller``: a door's or sign's mask
centre, or a floor pixel, visible in the first frame, 1-5 m away, reachable), but on
buildings from the held-out seed range. Each goal is tried by

- ``pixelnav``: the policy in closed loop, reset on the first frame's goal mask;
- ``geometric``: the geometric refiner's bearing and range on the first frame give a
  point; the body turns towards it and steps forward, stopping within ``stop_radius`` of
  it or when a step is blocked (the tree's approach, open loop, in discrete steps).

Success: the agent stops within ``SUCCESS_M`` of the goal point (in the plane) within
``MAX_STEPS`` actions. "Reached" counts coming that close at any time. A failure has a
reason (``FAILURES``): it stopped short (never that close), stopped after passing the
goal (was that close, stopped farther), or never stopped (passing the goal or not).
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import asdict, dataclass
from functools import partial

import numpy as np

from pmnav_bt.experiments.pixelnav_data import DataConfig, Roller, building_seed, make_building
from pmnav_bt.pixelnav.dataset import KINDS, MAX_STEPS
from pmnav_bt.seams import (
    Detection,
    DiscreteAction,
    MotionStatus,
    Observation,
    Pose2D,
)

SUCCESS_M = 1.0
FAILURES = ("stopped short", "stopped after passing", "no stop, passed", "no stop, never near")
BANDS = ((1.0, 2.0), (2.0, 3.0), (3.0, 4.0), (4.0, 5.0))


@dataclass
class Trial:
    method: str
    building: int
    kind: str
    distance: float  # straight-line start -> goal (m)
    success: bool
    reached: bool
    steps: int
    final_error: float  # m from the goal point where it stopped (or at the budget)

    @property
    def failure(self) -> str:
        """Why it failed (one of ``FAILURES``), or "" for a success."""
        if self.success:
            return ""
        if self.steps < MAX_STEPS:  # it stopped
            return FAILURES[1] if self.reached else FAILURES[0]
        return FAILURES[2] if self.reached else FAILURES[3]


def _first_obs(roller: Roller, pose: Pose2D, frame) -> Observation:
    return Observation(
        rgb=frame.rgb,
        pose=pose,
        stamp=0.0,
        intrinsics=roller.k_big,
        depth=frame.depth,
        segmentation=frame.segmentation,
        labels=dict(roller.world.labels),
    )


def _detection(mask: np.ndarray, kind: str) -> Detection:
    ys, xs = np.nonzero(mask)
    box = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    return Detection(kind, box, 1.0, mask=mask)


def run_policy(policy, roller: Roller, start: Pose2D, obs0: Observation, det: Detection, goal):
    """The policy from ``start``: (stopped, steps, reached) ."""
    base = roller.base
    base.set_pose(start)
    policy.reset(obs0, det)
    obs = obs0
    reached = False
    for step in range(MAX_STEPS):
        p = base.pose()
        reached |= math.hypot(goal[0] - p.x, goal[1] - p.y) <= SUCCESS_M
        a = policy.act(obs).action
        if a == DiscreteAction.STOP:
            return True, step + 1, reached
        base.execute(a)
        obs = base.observe()
    return False, MAX_STEPS, reached


def run_geometric(roller: Roller, start: Pose2D, obs0: Observation, det: Detection, goal, stop):
    """Turn to the refined point and step to it: (stopped, steps, reached)."""
    from pmnav_bt.geometry import wrap_angle
    from pmnav_bt.perception.refiners.geometric import GeometricRefiner
    from pmnav_bt.seams import TURN_STEP_RAD

    base = roller.base
    base.set_pose(start)
    ref = GeometricRefiner().refine(obs0, det)
    rng = ref.range if ref.range is not None else 0.0
    tx = start.x + rng * math.cos(start.yaw + ref.bearing)
    ty = start.y + rng * math.sin(start.yaw + ref.bearing)
    reached = False
    for step in range(MAX_STEPS):
        p = base.pose()
        reached |= math.hypot(goal[0] - p.x, goal[1] - p.y) <= SUCCESS_M
        if math.hypot(tx - p.x, ty - p.y) <= stop:
            return True, step + 1, reached
        err = wrap_angle(math.atan2(ty - p.y, tx - p.x) - p.yaw)
        if abs(err) > TURN_STEP_RAD / 2:
            base.execute(DiscreteAction.TURN_LEFT if err > 0 else DiscreteAction.TURN_RIGHT)
        elif base.execute(DiscreteAction.FORWARD) == MotionStatus.BLOCKED:
            return True, step + 1, reached  # against the wall or a door: as close as it gets
    return False, MAX_STEPS, reached


def trace_policy(policy, roller: Roller, start: Pose2D, obs0: Observation, det: Detection, goal):
    """The policy from ``start`` with STOP turned off, for ``MAX_STEPS`` steps: per step
    (STOP probability, steps left it expects, m from the goal before the step). Until a
    STOP rule fires the moves are those of a policy with that rule, so one trace answers
    every rule (``sweep``)."""
    base = roller.base
    base.set_pose(start)
    keep = policy.stop_threshold, policy.stop_steps
    policy.stop_threshold, policy.stop_steps = math.inf, None
    try:
        policy.reset(obs0, det)
        obs, rows = obs0, []
        for _ in range(MAX_STEPS):
            p = base.pose()
            err = math.hypot(goal[0] - p.x, goal[1] - p.y)
            step = policy.act(obs)
            rows.append((policy.last_stop_prob, step.steps_to_goal, err))
            base.execute(step.action)
            obs = base.observe()
    finally:
        policy.stop_threshold, policy.stop_steps = keep
    return rows


def stop_step(trace, threshold: float, steps: float | None) -> int | None:
    """The first step at which the rule (STOP probability >= ``threshold``, or at most
    ``steps`` steps left) stops, or None."""
    for i, (prob, left, _) in enumerate(trace):
        if prob >= threshold or (steps is not None and left <= steps):
            return i
    return None


def sweep(traces, thresholds, steps_options) -> list[dict]:
    """SR of each STOP rule on the same traces (success: stopped within ``SUCCESS_M``)."""
    rows = []
    for th in thresholds:
        for st in steps_options:
            ok = 0
            for tr in traces:
                i = stop_step(tr, th, st)
                ok += i is not None and tr[i][2] <= SUCCESS_M
            rows.append({"stop_threshold": th, "stop_steps": st, "sr": ok / max(1, len(traces))})
    return rows


VALIDATION_SHARDS = 73  # seed 0: shards 73-79 were the shipped model's validation split (74 shards)


def evaluate(
    policy,
    n_buildings: int,
    per_building: int,
    seed: int = 0,
    progress: bool = True,
    validation: bool = False,
    traces: list | None = None,
):
    """Trials of both methods on the same goals of held-out buildings (``validation``:
    of the buildings of training's validation shards instead, for calibration). With
    ``traces`` (a list), the policy's STOP-free traces are appended to it instead
    (``trace_policy``) and only the geometric trials are returned."""
    from tqdm import tqdm

    from pmnav_bt.sim.world import SimWorld

    cfg = DataConfig(seed=0 if validation else seed, heldout=not validation, noise=0.0)
    first = VALIDATION_SHARDS if validation else 0
    trials: list[Trial] = []
    bar = tqdm(total=n_buildings * per_building, unit="goal", disable=not progress)
    for b in range(n_buildings):
        bseed = building_seed(cfg, first + b)
        rng = np.random.default_rng([seed, b, 99])
        with SimWorld(make_building(bseed)) as world:
            roller = Roller(world, cfg)
            done = 0
            while done < per_building:
                start = roller.random_start(rng)
                frame = roller.first_frame(start)
                picked = roller.pick_goal(start, frame, rng)
                if picked is None:
                    continue
                kind, pt, mask = picked
                if roller.field(start, pt) is None:
                    continue
                obs0 = _first_obs(roller, start, frame)
                det = _detection(mask, KINDS[kind])
                dist = math.hypot(pt[0] - start.x, pt[1] - start.y)
                runs = {
                    "pixelnav": partial(run_policy, policy, roller, start, obs0, det, pt),
                    "geometric": partial(
                        run_geometric, roller, start, obs0, det, pt, cfg.stop_radius
                    ),
                }
                if traces is not None:
                    traces.append(trace_policy(policy, roller, start, obs0, det, pt))
                    del runs["pixelnav"]
                for method, fn in runs.items():
                    stopped, steps, reached = fn()
                    p = roller.base.pose()
                    err = math.hypot(pt[0] - p.x, pt[1] - p.y)
                    trials.append(
                        Trial(
                            method,
                            bseed,
                            KINDS[kind],
                            dist,
                            stopped and err <= SUCCESS_M,
                            reached or err <= SUCCESS_M,
                            steps,
                            err,
                        )
                    )
                done += 1
                bar.update(1)
            roller.base.close()
    bar.close()
    return trials


def table(trials: list[Trial]) -> list[dict]:
    """Rows: method x group (all, each distance band, each goal kind) -> n, SR, reached."""
    groups: dict[tuple[str, str], list[Trial]] = defaultdict(list)
    for t in trials:
        groups[(t.method, "all")].append(t)
        for lo, hi in BANDS:
            if lo <= t.distance < hi or (hi == BANDS[-1][1] and t.distance == hi):
                groups[(t.method, f"{lo:g}-{hi:g} m")].append(t)
        groups[(t.method, t.kind)].append(t)
    order = ["all"] + [f"{lo:g}-{hi:g} m" for lo, hi in BANDS] + list(KINDS)
    rows = []
    for method in ("pixelnav", "geometric"):
        for g in order:
            ts = groups.get((method, g), [])
            if not ts:
                continue
            rows.append(
                {
                    "method": method,
                    "group": g,
                    "n": len(ts),
                    "sr": float(np.mean([t.success for t in ts])),
                    "reached": float(np.mean([t.reached for t in ts])),
                    "steps": float(np.mean([t.steps for t in ts])),
                    "error_m": float(np.median([t.final_error for t in ts])),
                }
            )
    return rows


def failures(trials: list[Trial]) -> list[dict]:
    """Rows: method x failure reason -> count, and the median distance of those goals."""
    rows = []
    for method in ("pixelnav", "geometric"):
        ts = [t for t in trials if t.method == method]
        for why in FAILURES:
            fs = [t for t in ts if t.failure == why]
            rows.append(
                {
                    "method": method,
                    "failure": why,
                    "n": len(fs),
                    "of": len(ts),
                    "median_goal_m": float(np.median([t.distance for t in fs])) if fs else None,
                    "median_steps": float(np.median([t.steps for t in fs])) if fs else None,
                }
            )
    return rows


def format_failures(rows: list[dict]) -> str:
    by = {(r["method"], r["failure"]): r for r in rows}
    lines = [f"{'failures':<22} {'PixelNav':>8} {'geometric':>9}"]
    for why in FAILURES:
        p, q = by[("pixelnav", why)], by[("geometric", why)]
        lines.append(f"{why:<22} {p['n']:>8} {q['n']:>9}")
    return "\n".join(lines)


def format_table(rows: list[dict]) -> str:
    by = {(r["method"], r["group"]): r for r in rows}
    groups = list(dict.fromkeys(r["group"] for r in rows))
    lines = [
        f"{'goals':<10} {'n':>4}  {'PixelNav SR':>11} {'reached':>8} {'err m':>6}"
        f"  {'geometric SR':>12} {'reached':>8} {'err m':>6}"
    ]
    for g in groups:
        p, q = by.get(("pixelnav", g)), by.get(("geometric", g))
        n = (p or q)["n"]

        def cells(r):
            if r is None:
                return f"{'-':>11} {'-':>8} {'-':>6}"
            return f"{r['sr']:>11.1%} {r['reached']:>8.1%} {r['error_m']:>6.2f}"

        lines.append(f"{g:<10} {n:>4}  {cells(p)}  {' ' + cells(q)}")
    return "\n".join(lines)


def trials_json(trials: list[Trial]) -> list[dict]:
    return [asdict(t) | {"failure": t.failure} for t in trials]
