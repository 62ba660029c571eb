"""How much of real buildings 'pmnav map draft' finds, and how fast it drafts a big one.

Per real map: the draft's key waypoints, corridors and length; where a hand annotation
exists (tests/map/data/*_corridors.yaml), the coverage of the annotated corridor length
(a drafted centre line within 0.75 m) and the spurious fraction of the drafted length
(outside the annotated open areas); and the seconds it took. Then the time to draft and
validate a generated building of 100 m x 100 m (target: under 30 s on 2 cores).

    python benchmarks/bench_draft_coverage.py [--images /tmp] [--maps hospital willow ...]

Maps not in the repository (the RMF drawings, the CCIA university floor) are read from
../shared/maps or $PMNAV_SHARED_MAPS and left out, with a line saying so, when absent.
The RMF buildings are drafted twice: from their drawings, and from the walls grid
``pmnav map import-rmf`` writes (``*-walls`` rows), which is measured against the
building's robot lanes as imported (not a hand annotation: lanes run along most
corridors, but not all, and some run through halls).
``--images DIR`` writes DIR/draft_<map>_coverage.png: the grid, the annotation in red,
the draft in blue.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from shapely.geometry import LineString

from pmnav_bt.map.building import save_building
from pmnav_bt.map.checks import building_warnings
from pmnav_bt.map.draft import draft_building, draft_drawing
from pmnav_bt.map.draft_coverage import Annotation, load_annotation, measure
from pmnav_bt.map.floorplan import load_floor_plan, rasterize_building, save_ros_map
from pmnav_bt.map.generate import generate_building
from pmnav_bt.map.rmf_import import import_rmf, write_import

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "map" / "data"


def _shared() -> Path:
    env = os.environ.get("PMNAV_SHARED_MAPS")
    return Path(env) if env else ROOT.parent / "shared" / "maps"


# name: (source, drawing scale in m/px or None for a map_server grid, annotation or None)
MAPS = {
    "hospital": (ROOT / "examples/hospital/hospital.yaml", None, DATA / "hospital_corridors.yaml"),
    "willow": (ROOT / "examples/maps/willow/willow.yaml", None, DATA / "willow_corridors.yaml"),
    "stata": (ROOT / "examples/maps/stata/stata.yaml", None, DATA / "stata_corridors.yaml"),
    "ipa_office": (
        ROOT / "examples/maps/ipa_office/ipa_office.yaml", None, DATA / "ipa_office_corridors.yaml"
    ),
    "ccia": (_shared() / "ccia/ccia.yaml", None, None),
    # The drawings' scales from their .building.yaml measurements (pixel pairs and metres).
    "clinic": (_shared() / "rmf/clinic/clinic.png", 0.7 / 26.001, None),
    "office": (_shared() / "rmf/office/office.png", 20.089 / 2374.04, None),
}


# name: (RMF building file, level or None): drafted from the walls grid import-rmf writes
RMF_WALLS = {
    "clinic-L1-walls": (_shared() / "rmf/clinic/clinic.building.yaml", "L1"),
    "clinic-L2-walls": (_shared() / "rmf/clinic/clinic.building.yaml", "L2"),
    "office-walls": (_shared() / "rmf/office/office.building.yaml", None),
}


def _lanes(b) -> Annotation:
    """An imported RMF building's corridors (its lanes) as an annotation, no open areas."""
    pos = {w.id: w.pos for w in b.waypoints}
    return Annotation("", [LineString([pos[e.a], pos[e.b]]) for e in b.edges], [])


def _draw(b, base: Path, ann, path: Path) -> None:
    plan = load_floor_plan(b, base)
    img = plan.bgr().copy()
    pos = {w.id: w.pos for w in b.waypoints}

    def px(pts):
        return plan.world_to_pixel(pts).round().astype(np.int32)

    if ann is not None:
        for a in ann.open_areas:
            cv2.polylines(img, [px(np.array(a.exterior.coords))], True, (200, 0, 200), 2)
        for c in ann.corridors:
            cv2.polylines(img, [px(np.array(c.coords))], False, (0, 0, 230), 5)
    for e in b.edges:
        p = px([pos[e.a], pos[e.b]])
        cv2.line(img, tuple(p[0]), tuple(p[1]), (220, 120, 0), 2)
    cv2.imwrite(str(path), img)


def _one(name: str, images: Path | None, tmp: Path) -> str:
    if name in RMF_WALLS:
        src, level = RMF_WALLS[name]
    else:
        src, scale, ann_path = MAPS[name]
    if not src.is_file():
        return f"{name:15s} left out: {src} is absent"
    out = tmp / name / "building.yaml"
    out.parent.mkdir(parents=True, exist_ok=True)
    ann = None
    if name in RMF_WALLS:
        imp = import_rmf(src, tmp / name / "imported.yaml", level)
        write_import(imp, tmp / name / "imported.yaml")
        ann = _lanes(imp.building)
        src, scale = tmp / name / "imported_walls.yaml", None
    t = time.perf_counter()
    if scale is None:
        b, d, text = draft_building(src, out)
    else:
        b, d, text = draft_drawing(src, out, scale)
    secs = time.perf_counter() - t
    out.write_text(text, encoding="utf-8")
    if name not in RMF_WALLS and ann_path and ann_path.is_file():
        ann = load_annotation(ann_path)
    if images is not None:
        _draw(b, out.parent, ann, images / f"draft_{name}_coverage.png")
    length = sum(math.dist(b.waypoint(e.a).pos, b.waypoint(e.b).pos) for e in b.edges)
    row = f"{name:15s} {len(b.waypoints):5d} {len(b.edges):5d} {length:8.0f} "
    if ann is None:
        return row + f"{'-':>8s} {'-':>8s} {'-':>8s} {secs:6.1f}"
    m = measure(b, ann)
    cover, spur = 100 * m.coverage, 100 * m.spurious
    return row + f"{m.annotated_m:8.0f} {cover:7.1f}% {spur:7.1f}% {secs:6.1f}"


def _big(tmp: Path, side_m: float) -> str:
    """Draft and validate a generated building about ``side_m`` on a side."""
    side = 5  # junctions per side of the grid; the corridors between them span side_m
    b = generate_building(n_rooms=120, seed=3, spacing=side_m / (side - 1), min_side=side)
    plan = rasterize_building(b)
    w, h = plan.width * plan.resolution, plan.height * plan.resolution
    (tmp / "big").mkdir()
    grid = save_ros_map(plan, tmp / "big" / "grid.yaml")
    t = time.perf_counter()
    drafted, d, text = draft_building(grid, tmp / "big" / "building.yaml")
    out = tmp / "big" / "building.yaml"
    save_building(drafted, out)
    building_warnings(drafted, out.parent)
    secs = time.perf_counter() - t
    return (
        f"draft + validate of a generated {w:.0f} m x {h:.0f} m building "
        f"({plan.width} x {plan.height} px, {len(drafted.edges)} corridors): {secs:.1f} s"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    names = [*MAPS, *RMF_WALLS]
    ap.add_argument("--maps", nargs="+", default=names, choices=names)
    ap.add_argument("--images", type=Path, help="write draft_<map>_coverage.png here")
    ap.add_argument("--side", type=float, default=100.0, help="size of the timed building (m)")
    args = ap.parse_args()
    print(f"{'map':15s} {'wps':>5s} {'edges':>5s} {'drafted':>8s} {'annot.':>8s} "
          f"{'cover':>8s} {'spur.':>8s} {'s':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.maps:
            print(_one(name, args.images, Path(tmp)), flush=True)
        print(_big(Path(tmp), args.side))


if __name__ == "__main__":
    main()
