"""Sign reading: does the ``ocr`` grounder name the right room, how far, how fast.

Views of the sign plates of every built-in building are rendered from 1.5-6 m and 0-70
deg off the plate's normal (``sim.sign_views``), at 320x240 and 640x480. For each view
the grounder's ``read_signs`` names entities; a named entity is right when the frame
shows that entity's sign (its simulator label covers pixels inside the detection's box).
Recall: views whose target sign was named. Precision: named entities that were right.
False targets: named entities that were not right (the frame does not show their sign inside
the detection's box): each one a room the tree would take for another. The target is none.
Latency: wall time and process CPU time of ``read_signs`` per frame (the models are
loaded before timing; one onnxruntime thread). On a shared machine the wall time
includes waiting for a core: the load average is printed with it.

Recall is also given per plate kind (``read_range.plate_kind``: a bare number, a name with
short lines, a name with a long line set smaller); ``--kind`` renders views of one kind only.

Recall per angle off the plate's normal is printed too; ``--angles 0,88`` samples views
beyond the default 0-70 deg (a plate seen along its wall, e.g. from a junction), and
``--widths 640`` measures one camera size only.

Run: python benchmarks/bench_signs.py [--views 160] [--seed 0] [--kind "long name"]
     [--angles 0,70] [--widths 320,640]
Target: read_signs p50 < 150 ms and p95 < 400 ms per 320x240 frame on 2 cores.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections import defaultdict

import numpy as np

from pmnav_bt.map.catalogue import builtin_buildings
from pmnav_bt.perception.grounders.ocr import OcrGrounder
from pmnav_bt.perception.read_range import PLATE_KINDS, plate_kind
from pmnav_bt.seams import EntityKind, landmark_label, sign_label
from pmnav_bt.sim.sign_views import sample_views
from pmnav_bt.sim.world import SimWorld

BANDS = ((1.5, 2.5), (2.5, 3.5), (3.5, 4.5), (4.5, 6.0))
ANGLE_BANDS = ((0, 30), (30, 50), (50, 60), (60, 70), (70, 75), (75, 80), (80, 90))  # deg


def shows(obs, entity, box) -> bool:
    """Whether the frame shows ``entity``'s sign inside ``box`` (simulator labels)."""
    lab = sign_label(entity.id) if entity.kind == EntityKind.ROOM else landmark_label(entity.id)
    ids = [i for i, name in obs.labels.items() if name == lab]
    x0, y0, x1, y1 = (int(round(v)) for v in box)
    return bool(np.isin(obs.segmentation[y0 : y1 + 1, x0 : x1 + 1], ids).any())


def band_of(d: float) -> int:
    return next(i for i, (a, b) in enumerate(BANDS) if a <= d < b or (i == len(BANDS) - 1))


def recall_cells(counts: list) -> str:
    """One table row: recall and views per distance band ("-" where none were taken)."""
    return "  ".join(
        f"{100 * c['hit'] / c['views']:5.1f}% of {c['views']:3d}" if c["views"] else "    -       "
        for c in counts
    )


def run(
    width: int,
    height: int,
    views: int,
    seed: int,
    kind: str | None = None,
    angles: tuple[float, float] = (0.0, 70.0),
) -> None:
    names = builtin_buildings()
    per = math.ceil(views / len(names))
    stats = defaultdict(lambda: defaultdict(int))
    kinds = defaultdict(lambda: defaultdict(int))  # (plate kind, band) -> views, hits
    by_angle = defaultdict(lambda: defaultdict(int))  # (angle band, band) -> views, hits
    times: list[float] = []
    cpu: list[float] = []
    false_targets: list[str] = []
    total = 0
    for k, name in enumerate(names):
        world = SimWorld(name)
        g = OcrGrounder(world.building)
        select = None if kind is None else (lambda text: plate_kind(text) == kind)
        views_k = sample_views(
            world,
            per,
            width=width,
            height=height,
            seed=seed + k,
            select=select,
            angles=(math.radians(angles[0]), math.radians(angles[1])),
        )
        for v in views_k:
            obs = v.observation
            t0, c0 = time.perf_counter(), time.process_time()
            dets = g.read_signs(obs)
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            s = stats[band_of(v.distance)]
            s["views"] += 1
            s["hit"] += any(d.entity == v.entity for d in dets)
            kd = kinds[(plate_kind(v.text), band_of(v.distance))]
            kd["views"] += 1
            kd["hit"] += any(d.entity == v.entity for d in dets)
            deg = math.degrees(v.angle)
            ab = next(i for i, (a, b) in enumerate(ANGLE_BANDS) if a <= deg < b or b == 90)
            ad = by_angle[(ab, band_of(v.distance))]
            ad["views"] += 1
            ad["hit"] += any(d.entity == v.entity for d in dets)
            for d in dets:
                s["named"] += 1
                right = shows(obs, d.entity, d.box)
                s["right"] += right
                if not right:
                    false_targets.append(
                        f"{name}: read {d.label!r} as {d.entity.id}, view of {v.text!r}"
                    )
            total += 1
        world.close()
    ms = np.array(times) * 1000
    cpu_ms = np.array(cpu) * 1000
    only = "" if kind is None else f", {kind} plates only"
    print(
        f"\n{width}x{height}: {total} views, {len(names)} buildings, "
        f"{angles[0]:g}-{angles[1]:g} deg off the plate{only}"
    )
    print(
        f"{'distance':>10s} {'views':>6s} {'recall':>7s} {'named':>6s} {'precision':>9s} "
        f"{'false':>5s}"
    )
    tot = defaultdict(int)
    for i, (a, b) in enumerate(BANDS):
        s = stats[i]
        for key in ("views", "hit", "named", "right"):
            tot[key] += s[key]
        rec = 100 * s["hit"] / max(s["views"], 1)
        prec = 100 * s["right"] / s["named"] if s["named"] else float("nan")
        false = s["named"] - s["right"]
        print(
            f"{a:4.1f}-{b:3.1f} m {s['views']:6d} {rec:6.1f}% {s['named']:6d} {prec:8.1f}% "
            f"{false:5d}"
        )
    rec = 100 * tot["hit"] / max(tot["views"], 1)
    prec = 100 * tot["right"] / tot["named"] if tot["named"] else float("nan")
    false = tot["named"] - tot["right"]
    print(
        f"{'all':>10s} {tot['views']:6d} {rec:6.1f}% {tot['named']:6d} {prec:8.1f}% {false:5d}"
    )
    for f in false_targets:
        print(f"  false target: {f}")
    print("recall per plate kind (read_range.plate_kind):")
    for kind in PLATE_KINDS:
        print(f"{kind:>10s} " + recall_cells([kinds[(kind, i)] for i in range(len(BANDS))]))
    print("recall per angle off the plate's normal (rows) and distance band (columns):")
    for i, (a, b) in enumerate(ANGLE_BANDS):
        row = [by_angle[(i, j)] for j in range(len(BANDS))]
        if any(c["views"] for c in row):
            print(f"{a:>3d}-{b:<2d} deg " + recall_cells(row))
    for what, v in (("wall time", ms), ("CPU time", cpu_ms)):
        print(
            f"read_signs {what}: p50 {np.percentile(v, 50):.0f} ms, "
            f"p95 {np.percentile(v, 95):.0f} ms, max {v.max():.0f} ms per frame"
        )
    print(f"(load average during the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--views", type=int, default=160, help="views per resolution")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kind", choices=PLATE_KINDS, help="views of this plate kind only")
    ap.add_argument("--angles", default="0,70", help="deg off the plate's normal: LO,HI")
    ap.add_argument("--widths", default="320,640", help="camera widths (4:3 frames)")
    args = ap.parse_args()
    lo, hi = (float(v) for v in args.angles.split(","))
    if not 0.0 <= lo < hi < 90.0:
        ap.error(f"--angles must be LO,HI with 0 <= LO < HI < 90, not {args.angles!r}")
    for w in (int(v) for v in args.widths.split(",")):
        run(w, w * 3 // 4, args.views, args.seed, args.kind, (lo, hi))


if __name__ == "__main__":
    main()
