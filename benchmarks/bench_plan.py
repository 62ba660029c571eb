"""Parse and plan on generated buildings of 100, 1,000 and 10,000 rooms; print the times.

Targets on the 2-core CI machine: parse 1,000 rooms in under 1 s; a plan in under
10 ms (median). "load" is reading and validating the YAML file; "parse" is building
the semantic priori-map from the validated building.

    python benchmarks/bench_plan.py [--sizes 100 1000 10000] [--plans 200]
"""

from __future__ import annotations

import argparse
import random
import statistics
import tempfile
import time
from pathlib import Path

from pmnav_bt.map.building import save_building
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.generate import generate_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.planning.graph_planner import GraphPlanner


def _best_of(fn, repeat: int) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10000])
    ap.add_argument("--plans", type=int, default=200, help="plans timed per building")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    print(
        f"{'rooms':>6} {'segments':>8} {'load s':>8} {'parse s':>8} "
        f"{'plan med ms':>11} {'plan p95 ms':>11} {'steps med':>9}"
    )
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.sizes:
            path = save_building(generate_building(n, seed=args.seed), Path(tmp) / f"b{n}.yaml")
            repeat = 3 if n <= 1000 else 1
            t_load, b = _best_of(lambda p=path: load_building(p), repeat)
            t_parse, pm = _best_of(lambda b=b: parse_building(b), repeat)
            rng = random.Random(args.seed)
            planner = GraphPlanner()
            times, steps = [], []
            for _ in range(args.plans):
                start = f"seg{rng.randint(1, len(pm.segments))}"
                goal = rng.choice(b.rooms).id
                t = time.perf_counter()
                p = planner.plan(pm, start, goal)
                times.append(time.perf_counter() - t)
                steps.append(len(p.steps))
            times.sort()
            p95 = times[int(0.95 * (len(times) - 1))]
            print(
                f"{n:>6} {len(pm.segments):>8} {t_load:>8.3f} {t_parse:>8.3f} "
                f"{1e3 * statistics.median(times):>11.2f} {1e3 * p95:>11.2f} "
                f"{statistics.median(steps):>9.0f}"
            )
    print("targets: parse 1,000 rooms < 1 s; plan median < 10 ms")


if __name__ == "__main__":
    main()
