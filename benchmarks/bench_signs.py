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

``--world realistic`` renders the built-ins in the realistic preset instead
(``world.preset=realistic``: each building and world seed draws its own signage system,
``sim/scene/signage.py``; ``--world-seeds`` worlds per building, the views split among
them). Pictogram plates (toilets, in buildings that have them: the built-ins have few or
none, ``--buildings hospital_1000,...`` names others) are counted as their own kind,
``pictogram``, read by the pictogram reader (``perception/pictograms.py``;
``--pictograms off`` measures the grounder without it). Recall, precision and CPU time
are then also given per plate style: capital height, font, colour scheme and mounting
(landmarks' one-line plates apart). Each view that missed its plate is put down to where
the plate was lost: ``hidden`` (no pixel of it in the frame: a person or clutter in
front), ``not proposed`` (no candidate of ``SignReader.candidates`` covers it), ``not
read`` (a candidate covers it but no text was read there, nor a pictogram sighted),
``read, not named`` (text read that names nothing: garbled or ambiguous; or a pictogram
sighted where the map has several toilets alike) or ``named another`` (a false target).

Run: python benchmarks/bench_signs.py [--views 160] [--seed 0] [--kind "long name"]
     [--angles 0,70] [--widths 320,640] [--world realistic] [--world-seeds 3]
     [--buildings fig2_hospital,hospital_1000] [--pictograms on|off]
Target: read_signs p50 < 150 ms and p95 < 400 ms per 320x240 frame on 2 cores.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections import defaultdict

import numpy as np

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.catalogue import builtin_buildings
from pmnav_bt.map.signage import PlateStyle
from pmnav_bt.perception.grounders.ocr import OcrGrounder
from pmnav_bt.perception.pictograms import PictogramReader
from pmnav_bt.perception.read_range import PLATE_KINDS, plate_kind
from pmnav_bt.seams import EntityKind, landmark_label, sign_label
from pmnav_bt.sim.scene.signage import COLOUR_SCHEMES, BuildingSignage, resolve_signage
from pmnav_bt.sim.sign_views import sample_views
from pmnav_bt.sim.world import SimWorld

BANDS = ((1.5, 2.5), (2.5, 3.5), (3.5, 4.5), (4.5, 6.0))
ANGLE_BANDS = ((0, 30), (30, 50), (50, 60), (60, 70), (70, 75), (75, 80), (80, 90))  # deg
CAP_BINS_MM = (20, 35, 50, 65)  # capital heights of the realistic preset: 20-80 mm
STYLE_ATTRS = ("capitals", "font", "colours", "mounting")
LOST_STAGES = ("hidden", "not proposed", "not read", "read, not named", "named another")
KINDS = (*PLATE_KINDS, "pictogram")


def kind_of(text: str) -> str:
    """A plate's kind: ``read_range.plate_kind`` of its text, or "pictogram" (no text)."""
    return plate_kind(text) if text else "pictogram"


def plate_mask(obs, entity) -> np.ndarray:
    """The pixels of ``entity``'s sign in ``obs`` (simulator labels)."""
    lab = sign_label(entity.id) if entity.kind == EntityKind.ROOM else landmark_label(entity.id)
    ids = [i for i, name in obs.labels.items() if name == lab]
    return np.isin(obs.segmentation, ids)


def shows(obs, entity, box) -> bool:
    """Whether the frame shows ``entity``'s sign inside ``box`` (simulator labels)."""
    x0, y0, x1, y1 = (int(round(v)) for v in box)
    return bool(plate_mask(obs, entity)[y0 : y1 + 1, x0 : x1 + 1].any())


def band_of(d: float) -> int:
    return next(i for i, (a, b) in enumerate(BANDS) if a <= d < b or (i == len(BANDS) - 1))


def recall_cells(counts: list) -> str:
    """One table row: recall and views per distance band ("-" where none were taken)."""
    return "  ".join(
        f"{100 * c['hit'] / c['views']:5.1f}% of {c['views']:3d}" if c["views"] else "    -       "
        for c in counts
    )


def colour_name(style: PlateStyle) -> str:
    """The colour scheme of ``style`` by its name in ``COLOUR_SCHEMES``."""
    for name, pair in COLOUR_SCHEMES.items():
        if pair == (style.text_rgb, style.plate_rgb):
            return name
    return "other"


def cap_bin(cap: float) -> str:
    """The capital-height bin (mm) of a plate."""
    lo = next(a for a in reversed(CAP_BINS_MM) if cap * 1000 >= a or a == CAP_BINS_MM[0])
    hi = CAP_BINS_MM[CAP_BINS_MM.index(lo) + 1] if lo != CAP_BINS_MM[-1] else None
    return f"{lo}-{hi} mm" if hi else f">= {lo} mm"


def style_keys(entity, signage: BuildingSignage | None) -> dict[str, str]:
    """The style attributes a view is counted under: capitals, font, colours, mounting."""
    if signage is None or entity.kind != EntityKind.ROOM:
        return dict.fromkeys(STYLE_ATTRS, "landmark plate")
    st = signage.rooms[entity.id]
    return {
        "capitals": cap_bin(st.cap_height),
        "font": st.font,
        "colours": colour_name(st),
        "mounting": st.mounting,
    }


def where_lost(g: OcrGrounder, obs, entity, dets) -> str:
    """Why a view did not name its plate (module docstring): the stage that lost it."""
    mask = plate_mask(obs, entity)
    if not mask.any():
        return "hidden"
    if any(d.entity is not None and d.entity != entity and not shows(obs, d.entity, d.box)
           for d in dets):
        return "named another"
    found = [
        (b, lh)
        for b, lh in g.reader.candidates(obs.rgb)
        if mask[int(b[1]) : int(b[3]) + 1, int(b[0]) : int(b[2]) + 1].any()
    ]
    if not found:
        return "not proposed"
    if g.reader.read(obs.rgb, found):
        return "read, not named"
    boxes = [b for b, _ in found]
    picto = g.pictograms.read(obs.rgb, boxes) if g.pictograms is not None else []
    return "read, not named" if any(r.sighting for r in picto) else "not read"


def run(
    width: int,
    height: int,
    views: int,
    seed: int,
    kind: str | None = None,
    angles: tuple[float, float] = (0.0, 70.0),
    preset: str = "clean",
    world_seeds: int = 1,
    buildings: list[str] | None = None,
    pictograms: bool = True,
) -> None:
    names = buildings or builtin_buildings()
    scene = WorldConfig(preset=preset)
    seeds = world_seeds if preset != "clean" else 1
    per = math.ceil(views / (len(names) * seeds))
    stats = defaultdict(lambda: defaultdict(int))
    kinds = defaultdict(lambda: defaultdict(int))  # (plate kind, band) -> views, hits
    by_angle = defaultdict(lambda: defaultdict(int))  # (angle band, band) -> views, hits
    by_style = defaultdict(lambda: defaultdict(int))  # (attr, value, band) -> counts
    style_cpu = defaultdict(list)  # (attr, value) -> CPU ms per frame
    lost = defaultdict(lambda: defaultdict(int))  # stage -> band -> views
    times: list[float] = []
    cpu: list[float] = []
    false_targets: list[str] = []
    total = 0
    for k, name in enumerate(names):
        for ws in range(seeds):
            world = SimWorld(name, scene=scene, seed=ws)
            signage = resolve_signage(world.building, scene.signage, world.rng("signage"))
            g = OcrGrounder(world.building, pictograms=PictogramReader() if pictograms else None)

            def select(text: str) -> bool:
                return kind is None or kind_of(text) == kind

            views_k = sample_views(
                world,
                per,
                width=width,
                height=height,
                seed=seed + k + 1000 * ws,
                select=select,
                angles=(math.radians(angles[0]), math.radians(angles[1])),
            )
            for v in views_k:
                obs = v.observation
                t0, c0 = time.perf_counter(), time.process_time()
                dets = g.read_signs(obs)
                times.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
                band = band_of(v.distance)
                hit = any(d.entity == v.entity for d in dets)
                s = stats[band]
                s["views"] += 1
                s["hit"] += hit
                kd = kinds[(kind_of(v.text), band)]
                kd["views"] += 1
                kd["hit"] += hit
                deg = math.degrees(v.angle)
                ab = next(i for i, (a, b) in enumerate(ANGLE_BANDS) if a <= deg < b or b == 90)
                ad = by_angle[(ab, band)]
                ad["views"] += 1
                ad["hit"] += hit
                keys = style_keys(v.entity, signage)
                for attr, value in keys.items():
                    c = by_style[(attr, value, band)]
                    c["views"] += 1
                    c["hit"] += hit
                    style_cpu[(attr, value)].append(cpu[-1] * 1000)
                for d in dets:
                    s["named"] += 1
                    right = shows(obs, d.entity, d.box)
                    s["right"] += right
                    for attr, value in keys.items():
                        by_style[(attr, value, band)]["named"] += 1
                        by_style[(attr, value, band)]["right"] += right
                    if not right:
                        false_targets.append(
                            f"{name}: read {d.label!r} as {d.entity.id}, view of {v.text!r}"
                        )
                if not hit:
                    lost[where_lost(g, obs, v.entity, dets)][band] += 1
                total += 1
            world.close()
    ms = np.array(times) * 1000
    cpu_ms = np.array(cpu) * 1000
    only = "" if kind is None else f", {kind} plates only"
    print(
        f"\n{width}x{height}: {total} views, {len(names)} buildings, "
        f"{angles[0]:g}-{angles[1]:g} deg off the plate{only}, world {preset}, "
        f"pictogram reader {'on' if pictograms else 'off'}"
        + (f" ({seeds} world seeds a building)" if preset != "clean" else "")
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
    print("recall per plate kind (read_range.plate_kind; pictogram: no text):")
    for kind in KINDS:
        print(f"{kind:>10s} " + recall_cells([kinds[(kind, i)] for i in range(len(BANDS))]))
    print("recall per angle off the plate's normal (rows) and distance band (columns):")
    for i, (a, b) in enumerate(ANGLE_BANDS):
        row = [by_angle[(i, j)] for j in range(len(BANDS))]
        if any(c["views"] for c in row):
            print(f"{a:>3d}-{b:<2d} deg " + recall_cells(row))
    if preset != "clean":
        print("per plate style: recall per distance band, precision, CPU ms p50 per frame:")
        for attr in STYLE_ATTRS:
            values = sorted({v for a, v, _ in by_style if a == attr})
            for value in values:
                row = [by_style[(attr, value, j)] for j in range(len(BANDS))]
                named = sum(c["named"] for c in row)
                prec = f"{100 * sum(c['right'] for c in row) / named:5.1f}%" if named else "    -"
                p50 = np.percentile(style_cpu[(attr, value)], 50)
                print(
                    f"{attr:>9s} {value:>22s} " + recall_cells(row) + f"  {prec} {p50:4.0f} ms"
                )
    print("views that missed their plate, by where it was lost (per distance band):")
    for stage in LOST_STAGES:
        print(f"{stage:>16s} " + "  ".join(f"{lost[stage][j]:4d}" for j in range(len(BANDS))))
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
    ap.add_argument("--kind", choices=KINDS, help="views of this plate kind only")
    ap.add_argument("--angles", default="0,70", help="deg off the plate's normal: LO,HI")
    ap.add_argument("--widths", default="320,640", help="camera widths (4:3 frames)")
    ap.add_argument("--world", default="clean", choices=("clean", "realistic"),
                    help="world preset the built-ins are rendered in")
    ap.add_argument("--world-seeds", type=int, default=3,
                    help="realistic worlds (signage systems) per building")
    ap.add_argument("--buildings", help="comma-separated buildings (default: the built-ins)")
    ap.add_argument("--pictograms", default="on", choices=("on", "off"),
                    help="read pictogram plates (the ocr grounder's default) or not")
    args = ap.parse_args()
    if args.world_seeds < 1:
        ap.error(f"--world-seeds must be at least 1, not {args.world_seeds}")
    lo, hi = (float(v) for v in args.angles.split(","))
    if not 0.0 <= lo < hi < 90.0:
        ap.error(f"--angles must be LO,HI with 0 <= LO < HI < 90, not {args.angles!r}")
    for w in (int(v) for v in args.widths.split(",")):
        run(w, w * 3 // 4, args.views, args.seed, args.kind, (lo, hi), args.world,
            args.world_seeds, args.buildings.split(",") if args.buildings else None,
            args.pictograms == "on")


if __name__ == "__main__":
    main()
