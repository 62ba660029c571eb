"""Corner and opening checks from depth geometry against the simulator's masks.

Views are rendered in every built-in building, from the corridor graph: facing the wall
at the end of a turn (``corner``), along a corridor with at least 3.5 m of it ahead
(``straight``), and into a side corridor from a junction or turn (``opening``). Each
view is judged with the paper's mask-ratio rule (``perception.corner``) twice: on the
simulator's floor/wall labels and on the ``ocr`` grounder's surfaces from depth (clean,
and with a real depth camera's faults: 10 % of pixels without a return, 1 % range noise).
A view is right when the rule says corner for a corner and opening (not corner) for the
other two.

Run: python benchmarks/bench_surfaces.py [--per-class 70] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import random
from collections import defaultdict
from dataclasses import replace

import numpy as np

from pmnav_bt.map.catalogue import builtin_buildings
from pmnav_bt.perception.corner import MaskRatios, central_band, is_corner, is_opening
from pmnav_bt.perception.depth import surfaces
from pmnav_bt.seams import CameraIntrinsics, Observation, Pose2D
from pmnav_bt.sim.render import render_camera
from pmnav_bt.sim.robot import CAMERA_HEIGHT, HFOV, RADIUS
from pmnav_bt.sim.world import SimWorld

CLASSES = ("corner", "straight", "opening")


def _unit(a, b) -> np.ndarray:
    d = np.subtract(b, a)
    return d / np.linalg.norm(d)


def view_poses(world: SimWorld, rng: random.Random) -> dict[str, list[Pose2D]]:
    """Candidate poses per class from the building's corridor graph."""
    b = world.building
    pos = {w.id: np.asarray(w.pos, float) for w in b.waypoints}
    nbrs: dict[str, list[str]] = defaultdict(list)
    width: dict[tuple[str, str], float] = {}
    for e in b.edges:
        nbrs[e.a].append(e.b)
        nbrs[e.b].append(e.a)
        width[(e.a, e.b)] = width[(e.b, e.a)] = b.edge_width(e)
    out: dict[str, list[Pose2D]] = {c: [] for c in CLASSES}

    def pose(p: np.ndarray, d: np.ndarray, lateral: float = 0.0) -> Pose2D:
        n = np.array([-d[1], d[0]])
        q = p + lateral * n
        yaw = math.atan2(d[1], d[0]) + rng.uniform(-math.radians(5), math.radians(5))
        return Pose2D(float(q[0]), float(q[1]), yaw)

    for w, ns in nbrs.items():
        for nb in ns:
            d_in = _unit(pos[nb], pos[w])
            length = float(np.linalg.norm(pos[w] - pos[nb]))
            half = width[(nb, w)] / 2.0
            straight_on = any(float(_unit(pos[w], pos[o]) @ d_in) > 0.9 for o in ns if o != nb)
            if not straight_on:  # a wall ends this corridor at w: corner views
                for _ in range(3):
                    to_wall = rng.uniform(1.2, 3.0)
                    back = to_wall - half
                    if 0.0 < back < length:
                        lat = rng.uniform(-0.3, 0.3)
                        out["corner"].append(pose(pos[w] - back * d_in, d_in, lat))
            for _ in range(2):  # along the corridor towards w, >= 3.5 m of it ahead
                ahead = rng.uniform(3.5, 8.0)
                if ahead < length - 0.5:
                    lat = rng.uniform(-0.4, 0.4)
                    out["straight"].append(pose(pos[w] - ahead * d_in, d_in, lat))
            for o in ns:  # at w, looking into another corridor that is not straight on
                d_out = _unit(pos[w], pos[o])
                if o != nb and abs(float(d_out @ d_in)) < 0.5:
                    back = rng.uniform(0.0, 0.4)
                    out["opening"].append(pose(pos[w] - back * d_in, d_out, 0.0))
    return out


def ratios(mask_floor: np.ndarray, mask_wall: np.ndarray) -> MaskRatios:
    rows, cols = central_band(mask_floor.shape)
    area = (rows.stop - rows.start) * (cols.stop - cols.start)
    return MaskRatios(
        float(mask_wall[rows, cols].sum()) / area, float(mask_floor[rows, cols].sum()) / area
    )


def right(cls: str, r: MaskRatios) -> bool:
    return is_corner(r) if cls == "corner" else (is_opening(r) and not is_corner(r))


def faulty(obs: Observation, rng: np.random.Generator) -> Observation:
    """The frame as a real depth camera might give it: holes (NaN, 0) and range noise."""
    d = obs.depth * (1.0 + 0.01 * rng.standard_normal(obs.depth.shape)).astype(np.float32)
    holes = rng.random(d.shape)
    d[holes < 0.05] = np.nan
    d[(holes >= 0.05) & (holes < 0.10)] = 0.0
    return replace(obs, depth=d)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-class", type=int, default=70, help="views per class")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    nrng = np.random.default_rng(args.seed)
    k = CameraIntrinsics.from_hfov(args.width, args.height, HFOV)
    pool: dict[str, list[tuple[str, Pose2D]]] = {c: [] for c in CLASSES}
    worlds = {}
    for name in builtin_buildings():
        worlds[name] = SimWorld(name)
        for c, poses in view_poses(worlds[name], rng).items():
            pool[c] += [(name, p) for p in poses]
    tally = {c: defaultdict(int) for c in CLASSES}
    for c in CLASSES:
        rng.shuffle(pool[c])
        for name, p in pool[c]:
            if tally[c]["n"] >= args.per_class:
                break
            world = worlds[name]
            if world.clearance(p.x, p.y, RADIUS) < 0.02:
                continue
            f = render_camera(world, p.x, p.y, p.yaw, k, height=CAMERA_HEIGHT)
            labels = world.labels
            floor_ids = [i for i, lab in labels.items() if lab == "floor"]
            wall_ids = [i for i, lab in labels.items() if lab == "wall"]
            obs = Observation(f.rgb, p, 0.0, k, depth=f.depth, camera_height=CAMERA_HEIGHT)
            gt = ratios(np.isin(f.segmentation, floor_ids), np.isin(f.segmentation, wall_ids))
            s = surfaces(obs)
            dep = ratios(s.floor, s.wall)
            s2 = surfaces(faulty(obs, nrng))
            dep2 = ratios(s2.floor, s2.wall)
            t = tally[c]
            t["n"] += 1
            t["gt"] += right(c, gt)
            t["depth"] += right(c, dep)
            t["faulty"] += right(c, dep2)
            t["agree"] += right(c, gt) == right(c, dep)
    for w in worlds.values():
        w.close()
    print(f"corner/opening checks, {args.width}x{args.height}, mask-ratio rule of the paper")
    print(f"{'class':10s} {'views':>5s} {'sim masks':>10s} {'depth':>8s} {'depth+faults':>13s}")
    tot = defaultdict(int)
    for c in CLASSES:
        t = tally[c]
        n = max(t["n"], 1)
        for key in ("n", "gt", "depth", "faulty"):
            tot[key] += t[key]
        print(
            f"{c:10s} {t['n']:5d} {100 * t['gt'] / n:9.1f}% {100 * t['depth'] / n:7.1f}% "
            f"{100 * t['faulty'] / n:12.1f}%"
        )
    n = max(tot["n"], 1)
    print(
        f"{'all':10s} {tot['n']:5d} {100 * tot['gt'] / n:9.1f}% {100 * tot['depth'] / n:7.1f}% "
        f"{100 * tot['faulty'] / n:12.1f}%"
    )


if __name__ == "__main__":
    main()
