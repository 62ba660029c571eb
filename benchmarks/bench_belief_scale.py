"""What reading the odometry's distance from the looks costs the worker.

Until a straight drive at a wall measures the odometry's distance, ``UpdateBelief``'s
worker job tries each of ``DISTANCE_SCALES`` on a fork of the corridor belief
(``CorridorBelief.likeliest_scale``): each moves every position held and weighs every
hypothesis again. The robot waits for that job before it drives on, so its time is the
figure. The belief here is sign_sparse_2's worst case measured: looks up the bare middle
arm, at the cross and 3.4 m short of branch3, with a depth ray every metre between
them, on odometry 9 % long. CPU seconds (the process's), so the figure holds on a busy
machine.

    python benchmarks/bench_belief_scale.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import time

from pmnav_bt.behaviours.active_localize import DISTANCE_SCALES, DISTANCE_SIGMA
from pmnav_bt.geometry import se2_compose
from pmnav_bt.map.generate import generate_sign_sparse
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.belief import CorridorBelief, Glimpse
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D

ODOM_T_MAP = (3.0, -2.0, 0.7)
LONG = 1.09
PATH = [(30.0, 7.8, math.pi / 2), (30.0, 30.0, math.pi / 2), (30.0, 30.0, 0.0), (56.6, 30.0, 0.0)]


def free_along(corridors, xy, h: float) -> float:
    """The free floor (m) along heading ``h`` from ``xy`` (map), to 0.25 m."""
    import shapely

    for i in range(1, 200):
        p = (xy[0] + 0.25 * i * math.cos(h), xy[1] + 0.25 * i * math.sin(h))
        if not corridors.covers(shapely.Point(*p)):
            return 0.25 * (i - 1)
    return 50.0


def build(pm) -> CorridorBelief:
    corridors = Visibility.of(pm).corridors
    b = CorridorBelief(pm)
    odo = PATH[0]
    for k, true in enumerate(PATH):
        if k:
            a = PATH[k - 1]
            steps = int(math.hypot(true[0] - a[0], true[1] - a[1]))
            for j in range(1, steps):  # a ray a metre along the drive
                t = (a[0] + (true[0] - a[0]) * j / steps, a[1] + (true[1] - a[1]) * j / steps)
                o = (odo[0] + LONG * (t[0] - a[0]), odo[1] + LONG * (t[1] - a[1]), true[2])
                pose = se2_compose(ODOM_T_MAP, o)
                b.observe_ray(Pose2D(*pose), free_along(corridors, t, true[2]), pose[2])
            odo = (odo[0] + LONG * (true[0] - a[0]), odo[1] + LONG * (true[1] - a[1]), true[2])
        pose = se2_compose(ODOM_T_MAP, odo)
        free = tuple(
            (
                true[2] + q * math.pi / 2 + ODOM_T_MAP[2],
                free_along(corridors, true, true[2] + q * math.pi / 2),
            )
            for q in range(4)
        )
        b.observe(Glimpse(Pose2D(*pose), {}, None, free), axis_odom=pose[2])
    return b


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    pm = parse_building(generate_sign_sparse(2))
    b = build(pm)
    print(f"belief: {len(b.logw)} hypotheses, {len(b.glimpses)} looks, {len(b.rays)} rays")
    rows = []
    for _ in range(args.repeat):
        t0 = time.process_time()
        f = b.fork()
        f.rescale(b.gain, 0.96)  # one scale: move and weigh everything again
        t1 = time.process_time()
        best = b.likeliest_scale(DISTANCE_SCALES, DISTANCE_SIGMA)
        t2 = time.process_time()
        rows.append((t1 - t0, t2 - t1))
    one = min(r[0] for r in rows)
    fit = min(r[1] for r in rows)
    print(f"{'one scale (s)':>16} {'all scales (s)':>16} {'scales':>7} {'chosen':>7}")
    print(f"{one:16.2f} {fit:16.2f} {len(DISTANCE_SCALES):7d} {best.scale:7.2f}")


if __name__ == "__main__":
    main()
