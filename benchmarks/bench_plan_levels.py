"""Plan across the levels of a generated site: 10 levels of 1,000 rooms each; print the times.

Target (issue 40): a plan across levels in under 10 ms (median). Each level is a
generated building (``generate_building``, a seed per level) with its elevators; every
lift has a lobby on each level (lift k: the k-th elevator of each level), and one more
serves the lower half only. A plan starts on a random segment of a random level and
goes to a random room of another level, named as a person qualifies it ("L7/room123");
the time covers resolving the goal, choosing the lifts and planning every leg, after one
plan per level has built the caches a long-lived planner keeps (each level's name index
and corridor lists, and the site map's lobby trees: one corridor search per lift's lobby,
``SiteMap.lobby_tree``). "site s" is validating the site (every level's building) and
parsing every level's priori-map; "warm s" is those first plans, one per level, the
lobby trees' cost included.

    python benchmarks/bench_plan_levels.py [--levels 10] [--rooms 1000] [--plans 200]
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from pmnav_bt.map.generate import generate_building
from pmnav_bt.map.site import site_from_data
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.planning.site_plan import SitePlanner


def site_data(levels: int, rooms: int, seed: int) -> dict:
    """A site file's data: ``levels`` generated levels of ``rooms`` rooms, joined by lifts."""
    entries, elevators = [], []
    for k in range(levels):
        b = generate_building(rooms, seed=seed + k, name=f"level{k + 1}")
        entries.append({"name": f"L{k + 1}", "elevation": 4.0 * k, "building": b.to_dict()})
        elevators.append([lm.id for lm in b.landmarks if lm.kind == "elevator"])
    banks = min(len(e) for e in elevators)
    lifts = [
        {"id": f"lift{j + 1}", "lobbies": {f"L{k + 1}": elevators[k][j] for k in range(levels)}}
        for j in range(banks)
    ]
    if levels >= 4:  # a lift of the lower half only, in the first bank's shaft
        half = {f"L{k + 1}": elevators[k][0] for k in range(levels // 2)}
        lifts.append({"id": "lift_low", "lobbies": half})
    return {"site_version": 1, "name": "bench_site", "levels": entries, "lifts": lifts}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, default=10)
    ap.add_argument("--rooms", type=int, default=1000, help="rooms per level")
    ap.add_argument("--plans", type=int, default=200, help="plans timed")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    if args.levels < 2 or args.rooms < 1 or args.plans < 1:
        ap.error("--levels must be at least 2, --rooms and --plans at least 1")

    data = site_data(args.levels, args.rooms, args.seed)
    t = time.perf_counter()
    sm = parse_site(site_from_data(data, "bench_site"))
    t_site = time.perf_counter() - t
    rng = random.Random(args.seed)
    planner = SitePlanner()
    names = sm.site.level_names
    t = time.perf_counter()
    for here, there in zip(names, names[1:] + names[:1], strict=True):  # warm each level's
        planner.plan(sm, here, "seg1", f"{there}/{sm.maps[there].building.rooms[0].id}")
    t_warm = time.perf_counter() - t
    times, cpu, rides, legs = [], [], [], []
    for _ in range(args.plans):
        here, there = rng.sample(names, 2)
        pm = sm.maps[here]
        start = f"seg{rng.randint(1, len(pm.segments))}"
        goal = f"{there}/{rng.choice(sm.maps[there].building.rooms).id}"
        t, c = time.perf_counter(), time.process_time()
        p = planner.plan(sm, here, start, goal)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        rides.append(len(p.rides))
        legs.append(sum(len(leg.plan.steps) for leg in p.legs))
    times.sort()
    p95 = times[int(0.95 * (len(times) - 1))]
    segments = sum(len(pm.segments) for pm in sm.maps.values())
    print(
        f"{'levels':>6} {'rooms':>6} {'lifts':>5} {'segments':>8} {'site s':>7} {'warm s':>6} "
        f"{'plan med ms':>11} {'plan p95 ms':>11} {'cpu med ms':>10} {'rides med':>9} "
        f"{'steps med':>9}"
    )
    print(
        f"{args.levels:>6} {args.levels * args.rooms:>6} {len(sm.site.lifts):>5} {segments:>8} "
        f"{t_site:>7.2f} {t_warm:>6.2f} {1e3 * statistics.median(times):>11.2f} {1e3 * p95:>11.2f} "
        f"{1e3 * statistics.median(cpu):>10.2f} {statistics.median(rides):>9.0f} "
        f"{statistics.median(legs):>9.0f}"
    )
    print(
        f"{args.plans} plans; target: plan median < 10 ms (cpu: this process's processor "
        "time, which a busy machine does not inflate)"
    )


if __name__ == "__main__":
    main()
