"""CPU time of the local planner's parts, on frames of a realistic world.

The local planner (``pmnav_bt/local_planner``) splits its work by where it runs
(docs/architecture.md, a tick never blocks):

- in the worker, with each watch frame (once a second): the costmap takes the frame in
  (``LocalCostmap.add_depth``: marking, clearing, inflation) and the way is judged
  (``passable`` and the navigation function, scikit-fmm);
- in the tick (10 Hz): the dynamic window (``dwa.choose``: 90-110 samples rolled out
  over 1.8 s and scored), the only part with a tick budget (a few ms).

The frames are a drive along fig2_hospital's first corridor in the realistic preset
(clutter, people), 320 x 240 depth as the evaluation renders it.

    python benchmarks/bench_local_planner.py [--frames 30] [--building fig2_hospital]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from pmnav_bt.config import WorldConfig
from pmnav_bt.local_planner.costmap import LocalCostmap
from pmnav_bt.local_planner.dwa import Dynamics, choose, navigation, passable
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.world import SimWorld


def cpu_ms(fn, repeat: int = 1) -> float:
    t = time.process_time()
    for _ in range(repeat):
        fn()
    return (time.process_time() - t) * 1000.0 / repeat


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--building", default="fig2_hospital")
    args = ap.parse_args()

    world = SimWorld(load_building(args.building), scene=WorldConfig(preset="realistic"), seed=0)
    start = world.start_pose()
    base = SimBase(world, pose=start, width=320, height=240)
    cm = LocalCostmap()
    dyn = Dynamics()
    add, judge, tick = [], [], []
    for k in range(args.frames):
        pose = Pose2D(start.x + 0.3 * k * math.cos(start.yaw),
                      start.y + 0.3 * k * math.sin(start.yaw), start.yaw)  # fmt: skip
        base.set_pose(pose)
        obs = base.observe()
        add.append(cpu_ms(lambda obs=obs, k=k: cm.add_depth(obs, float(k))))
        goal = (pose.x + 6.0 * math.cos(pose.yaw), pose.y + 6.0 * math.sin(pose.yaw))
        line = ((pose.x, pose.y), goal)
        grid = cm.snapshot()
        holder = {}

        def way(grid=grid, pose=pose, goal=goal, line=line, holder=holder):
            holder["ok"] = ok = passable(grid, line)
            holder["nav"] = navigation(grid, pose.x, pose.y, goal, ok)

        judge.append(cpu_ms(way))
        here = (pose.x, pose.y, pose.yaw)
        nav, ok = holder["nav"], holder["ok"]
        tick.append(
            cpu_ms(lambda grid=grid, nav=nav, ok=ok, here=here, goal=goal, line=line: choose(
                grid, nav, here, (0.2, 0.0), goal, line, dyn, ok), repeat=10)  # fmt: skip
        )
    base.close()
    world.close()

    def row(name: str, ms: list[float], where: str) -> str:
        p99 = float(np.percentile(ms, 99))
        return (f"  {name:<34} {statistics.mean(ms):6.2f} ms mean  {p99:6.2f} ms p99  ({where})")

    n = cm.n
    print(f"local planner, CPU time per call ({args.frames} frames of {args.building}, "
          f"realistic, 320x240 depth; window {n}x{n} cells):")  # fmt: skip
    print(row("costmap: add a depth frame", add, "worker, 1 Hz"))
    print(row("way judged: passable + navigation", judge, "worker, 1 Hz"))
    print(row("DWA: choose a command", tick, "tick, 10 Hz"))


if __name__ == "__main__":
    main()
