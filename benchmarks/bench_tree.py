"""Tick latency and episode wall time of the PM-Nav tree in the simulator.

Target (docs/architecture.md, a tick never blocks): p99 tick duration < 5 ms while workers are
busy. Two worker modes are measured:

- deferred (the simulator's mode): background jobs run between ticks;
- immediate (the robot's mode): jobs run in a worker thread *during* ticks. Here the
  worker renders pybullet frames, which hold Python's interpreter lock, so this is
  a pessimistic figure for the robot, whose worker decodes images and runs models.

The sign_sparse_2 case starts with no sign in reach: the corridor belief is built,
weighed with each look (``UpdateBelief``, in the worker) and with the depth along each
drive (``behaviours/follow_lead.py``), which is where the slowest ticks were.

    python benchmarks/bench_tree.py [--episodes 4] [--case sign_sparse_2] [--set k=v]
"""

from __future__ import annotations

import argparse
import statistics
import time

from pmnav_bt.config import load_config
from pmnav_bt.experiments.evaluation import custom_episode


def run(ep, deferred: bool, overrides=()) -> tuple[list[float], float, bool, int]:
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.sim.odometry import simulated_robot
    from pmnav_bt.sim.world import SimWorld
    from pmnav_bt.trees.runner import make_context, run_tree

    cfg = load_config(None, list(overrides))
    b = load_building(ep.building)
    pm = parse_building(b)
    durations: list[float] = []
    t0 = time.perf_counter()
    with SimWorld(b) as world:
        _, base = simulated_robot(world, cfg.sim, ep.start_pose, ep.seed)
        ctx = make_context(
            base, pm, cfg, seed=ep.seed, budget=ep.step_budget * 2, deferred_work=deferred
        )
        out = run_tree(ctx, ep.goal, tick_durations=durations)
    return durations, time.perf_counter() - t0, out.success, out.ticks


def pct(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q * (len(xs) - 1) + 0.5))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=4)
    ap.add_argument("--case", default=None, help="only the cases in this building")
    ap.add_argument("--set", action="append", default=[], help="config override key=value")
    args = ap.parse_args()
    from pmnav_bt.registry import grounder_label

    print(f"grounder: {grounder_label(load_config(None, args.set).grounder.backend)}")
    cases = [
        ("fig2_hospital", "room17", "22,0,0"),
        ("fig2_hospital", "room17", None),
        ("loop_school", "room10", None),
        ("sign_sparse_2", "room7", "30,35.5,-90"),
    ][: args.episodes]
    if args.case:
        cases = [c for c in cases if c[0] == args.case]
    print(
        f"{'episode':<34} {'mode':<9} {'ticks':>6} {'median ms':>9} {'p99 ms':>7} "
        f"{'max ms':>7} {'wall s':>7} {'sim s/wall s':>12} ok"
    )
    for building, goal, start in cases:
        ep = custom_episode(building, goal, start)
        for deferred in (True, False):
            d, wall, ok, ticks = run(ep, deferred, args.set)
            ms = [1e3 * x for x in d]
            name = f"{building}:{goal} from {start or 'start'}"
            print(
                f"{name:<34} {'deferred' if deferred else 'immediate':<9} {ticks:>6} "
                f"{statistics.median(ms):>9.3f} {pct(ms, 0.99):>7.2f} {max(ms):>7.1f} "
                f"{wall:>7.1f} {ticks * 0.1 / wall:>12.1f} {ok}"
            )
    print("target: p99 tick < 5 ms")


if __name__ == "__main__":
    main()
