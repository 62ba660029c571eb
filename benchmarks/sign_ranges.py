"""How far the ``ocr`` reader names plates of each size and font: the table ``read_range`` reads.

``bench_signs.py`` measures the simulator's first plates (0.8 m wide, 86 mm Hershey
capitals); real buildings hang plates of 0.15-0.45 m with 20-80 mm capitals in many faces
(``sim/scene/signage.py``, the realistic preset). Here every built-in building is given
one signage style at a time through its file's ``signage:`` section (beside the door, at
1.5 m, number and name; a colour scheme drawn per style), for each font of
``map.signage.SIGN_FONTS`` and each capital height of ``CAP_HEIGHTS_M``, and views of its
plates are rendered from each distance band of ``BANDS`` (``sim.sign_views``, 0-70 deg
off the plate's normal unless ``--angles``) at each camera width. A view counts as read
when ``read_signs`` names the plate's room.

The counts go to ``pmnav_bt/data/sign_ranges.json``: per (font, capital height, camera
width) the views and the reads per band. ``perception/read_range.py`` reads it: how far a
plate whose capitals are this tall is read at least ``recall`` of the time
(``plate_read_range``), pooled over the fonts (the face is not known before the plate is
read). The tree's active read (``behaviours/active_read.py``) drives that near an unread
plate.

Run: python benchmarks/sign_ranges.py [--per-band 6] [--seed 0] [--widths 320,640]
     [--angles 0,70] [--out PATH]
(2016 views with the defaults: 47 min on a loaded 2-core machine; writes
pmnav_bt/data/sign_ranges.json).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from pmnav_bt.loading import atomic_write_text
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.signage import SIGN_FONTS, Signage, SignStyleSpec
from pmnav_bt.perception.grounders.ocr import OcrGrounder
from pmnav_bt.perception.read_range import SIGN_RANGES_FILE
from pmnav_bt.seams import sign_label
from pmnav_bt.sim.scene.signage import CAP_PER_WIDTH, COLOUR_SCHEMES, PLATE_WIDTH_M
from pmnav_bt.sim.sign_views import sample_views
from pmnav_bt.sim.world import SimWorld

# Capital heights (m) across the realistic preset's 20-80 mm (sim/scene/signage.py).
CAP_HEIGHTS_M = (0.025, 0.04, 0.055, 0.07)
BANDS = ((0.75, 1.25), (1.25, 1.75), (1.75, 2.5), (2.5, 3.5), (3.5, 4.5), (4.5, 6.0))
PLATE_Z_M = 1.5  # plate centre: within the realistic preset's 1.35-1.7 m wall plates


def style(font: str, cap: float, rng: np.random.Generator) -> Signage:
    """A building's signage of ``font`` with ``cap`` m capitals: the plate as wide as the
    capitals need (``CAP_PER_WIDTH``) and the preset allows, a colour scheme drawn."""
    text_rgb, plate_rgb = list(COLOUR_SCHEMES.values())[int(rng.integers(len(COLOUR_SCHEMES)))]
    width = float(rng.uniform(max(PLATE_WIDTH_M[0], cap / CAP_PER_WIDTH), PLATE_WIDTH_M[1]))
    spec = SignStyleSpec(
        plate_width=round(width, 3),
        cap_height=cap,
        font=font,
        text_rgb=text_rgb,
        plate_rgb=plate_rgb,
        mounting="beside",
        layout="number_and_name",
        height=PLATE_Z_M,
    )
    return Signage(style=spec)


def line_height_m(g: OcrGrounder, obs, entity) -> float | None:
    """The text-line height (m) the reader's candidate finder gives the plate of ``entity``
    in ``obs`` (its line height in pixels at the plate's depth): what the robot knows of a
    plate's size before reading it. None where no candidate covers the plate."""
    ids = [i for i, name in obs.labels.items() if name == sign_label(entity.id)]
    mask = np.isin(obs.segmentation, ids)
    if not mask.any():
        return None
    ys, xs = np.nonzero(mask)
    for (x0, y0, x1, y1), lh in g.reader.candidates(obs.rgb):
        if x0 <= xs.mean() <= x1 and y0 <= ys.mean() <= y1:
            return float(lh * np.median(obs.depth[mask]) / obs.intrinsics.fy)
    return None


def measure(world: SimWorld, width: int, args, k: int, heights: list) -> tuple[list, list]:
    """Views and reads per band of ``world``'s plates seen ``width`` px wide; the measured
    line height of each plate found goes to ``heights``."""
    g = OcrGrounder(world.building)
    views, reads = [0] * len(BANDS), [0] * len(BANDS)
    for i, (a, b) in enumerate(BANDS):
        for v in sample_views(
            world,
            args.per_band,
            width=width,
            height=width * 3 // 4,
            distances=(a, b),
            angles=(math.radians(args.angles[0]), math.radians(args.angles[1])),
            seed=args.seed + 100 * k + i,
        ):
            views[i] += 1
            reads[i] += any(d.entity == v.entity for d in g.read_signs(v.observation))
            h = line_height_m(g, v.observation, v.entity)
            if h is not None:
                heights.append(h)
    return views, reads


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-band", type=int, default=6, help="views per band, font and size")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--widths", default="320,640", help="camera widths (4:3 frames)")
    ap.add_argument("--angles", default="0,70", help="deg off the plate's normal: LO,HI")
    ap.add_argument("--out", type=Path, default=SIGN_RANGES_FILE)
    args = ap.parse_args()
    args.angles = tuple(float(v) for v in args.angles.split(","))
    if len(args.angles) != 2 or not 0.0 <= args.angles[0] < args.angles[1] < 90.0:
        ap.error("--angles must be LO,HI with 0 <= LO < HI < 90")
    widths = [int(w) for w in args.widths.split(",")]
    rng = np.random.default_rng(args.seed)
    cells = []
    t0 = time.time()
    names = builtin_buildings()
    for k, (cap, font) in enumerate((c, f) for c in CAP_HEIGHTS_M for f in SIGN_FONTS):
        building = load_building(names[k % len(names)])
        world = SimWorld(building.model_copy(update={"signage": style(font, cap, rng)}))
        for width in widths:
            heights: list[float] = []
            views, reads = measure(world, width, args, k, heights)
            cells.append(
                {"font": font, "cap_height_m": cap, "width": width, "views": views,
                 "reads": reads, "line_height_m": round(float(np.median(heights)), 4)
                 if heights else None, "line_heights": len(heights)}
            )
            rec = " ".join(f"{r}/{v}" for r, v in zip(reads, views, strict=True))
            print(f"{width:4d} px {1000 * cap:3.0f} mm {font:>22s}: {rec}", flush=True)
        world.close()
    table = {
        "made_by": "benchmarks/sign_ranges.py",
        "seed": args.seed,
        "per_band": args.per_band,
        "angles_deg": list(args.angles),
        "plate_z_m": PLATE_Z_M,
        "bands_m": [list(b) for b in BANDS],
        "cells": cells,
    }
    atomic_write_text(args.out, json.dumps(table, indent=1) + "\n")
    print(f"{len(cells)} cells ({time.time() - t0:.0f} s) -> {args.out}")
    print("measured line height / capital height per capital height (cells' medians):")
    for cap in CAP_HEIGHTS_M:
        r = [c["line_height_m"] / cap for c in cells if c["cap_height_m"] == cap
             and c["line_height_m"] is not None]
        if r:
            print(f"  {1000 * cap:3.0f} mm: median {np.median(r):.2f}, "
                  f"{min(r):.2f}-{max(r):.2f} over {len(r)} cells")
    print("recall pooled over fonts, per capital height (rows) and band (columns):")
    for width in widths:
        for cap in CAP_HEIGHTS_M:
            mine = [c for c in cells if c["width"] == width and c["cap_height_m"] == cap]
            v = np.sum([c["views"] for c in mine], axis=0)
            r = np.sum([c["reads"] for c in mine], axis=0)
            row = "  ".join(f"{100 * a / max(b, 1):5.1f}%" for a, b in zip(r, v, strict=True))
            print(f"{width:4d} px {1000 * cap:3.0f} mm  {row}")


if __name__ == "__main__":
    main()
