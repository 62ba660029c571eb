"""Doors seen along the walls (``perception.door_sightings``): how often, how far, how wrong.

Views are rendered in the simulator from random points of the corridors' centre lines,
looking along the corridor either way or at a random heading. A door (or a landmark:
an elevator's doors, a stair) is in view when its simulator label covers at least
``--min-px`` pixels at door-handle height (the detector's band) within the range; it
is found when a detection lies within 0.6 m of its centre on the floor plane. A
detection with no door or landmark within 1 m is spurious. The simulator's labels only
score the detector: it sees RGB and depth.

Run: python benchmarks/bench_door_sightings.py [--views 200] [--seed 0]
     [--buildings all,sign_sparse_0,sign_sparse_1,sign_sparse_2] [--range 14]
     [--walls grid] [--image docs/img/door_sightings.png]  (example views, doors boxed)
     [--world realistic]  (furnished corridors: clutter, open doors, two-tone walls; the
     scene drawn from --seed)
Views are 320x240 as in the tree (``sim.width``); ``--width 640 --height 480`` for more.
Prints recall per distance band, spurious detections per view and ms per frame.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.catalogue import builtin_buildings, load_building, resolve_building_path
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.perception.depth import back_project, surfaces
from pmnav_bt.perception.door_sightings import BAND_M, find_doors
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.world import SimWorld

BANDS = (0.0, 4.0, 7.0, 10.0, 13.0, 16.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--views", type=int, default=200, help="views per building")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--buildings", default="all,sign_sparse_0,sign_sparse_1,sign_sparse_2")
    ap.add_argument("--range", type=float, default=14.0, help="look this far (m)")
    ap.add_argument("--min-px", type=int, default=30, help="label pixels for 'in view'")
    ap.add_argument("--width", type=int, default=320, help="camera pixels (the tree's views)")
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--walls", default="corridors", help="corridors or grid (sim.walls)")
    ap.add_argument(
        "--world", default="clean", help="world preset: clean or realistic (docs/worlds.md)"
    )
    ap.add_argument("--image", default="", help="write two example views here, doors boxed")
    ap.add_argument("--show-spurious", action="store_true", help="print each spurious one")
    args = ap.parse_args()
    if args.image:
        write_examples(args.image, args.width, args.height, args.range)
    names = []
    for n in args.buildings.split(","):
        names += list(builtin_buildings()) if n == "all" else [n]
    rng = np.random.default_rng(args.seed)
    seen = np.zeros(len(BANDS) - 1)
    found = np.zeros(len(BANDS) - 1)
    spurious, views, ms = 0, 0, []
    for name in names:
        path = resolve_building_path(name)
        building = load_building(path)
        vis = Visibility.of(parse_building(building))
        pts = vis.lattice_points
        scene = WorldConfig(preset=args.world)
        with SimWorld(
            building, walls=args.walls, base_dir=path.parent, scene=scene, seed=args.seed
        ) as world:
            items = list(world.doors.values()) + list(world.landmarks.values())
            centres = np.array([it.centre for it in items])
            base = SimBase(world, width=args.width, height=args.height)
            b_seen, b_found, b_spur = np.zeros_like(seen), np.zeros_like(found), 0
            for _ in range(args.views):
                p = pts[int(rng.integers(len(pts)))]
                heading = building_heading(vis, p)
                yaw = heading + (math.pi if rng.random() < 0.5 else 0.0)
                if rng.random() < 0.3:
                    yaw = float(rng.uniform(-math.pi, math.pi))
                x, y = vis.lattice_xy[p.index]
                base.set_pose(Pose2D(float(x), float(y), yaw))
                obs = base.observe()
                t0 = time.perf_counter()
                doors = find_doors(obs, surfaces(obs).wall, args.range)
                ms.append((time.perf_counter() - t0) * 1000.0)
                c, s = math.cos(yaw), math.sin(yaw)
                got = np.array(
                    [
                        (
                            x + c * d.centre[0] - s * d.centre[1],
                            y + s * d.centre[0] + c * d.centre[1],
                        )
                        for d in doors
                    ]
                ).reshape(-1, 2)
                height = back_project(obs)[..., 2] + obs.camera_height
                band = (np.nan_to_num(height, nan=-1) > BAND_M[0]) & (height < BAND_M[1])
                band &= np.nan_to_num(obs.depth, nan=1e9) <= args.range
                for it, ctr in zip(items, centres, strict=True):
                    lid = next((k for k, v in obs.labels.items() if v == it.label), None)
                    if lid is None or ((obs.segmentation == lid) & band).sum() < args.min_px:
                        continue
                    dist = math.hypot(ctr[0] - x, ctr[1] - y)
                    k = min(np.searchsorted(BANDS, dist, side="right") - 1, len(BANDS) - 2)
                    b_seen[k] += 1
                    if len(got) and np.min(np.linalg.norm(got - ctr, axis=1)) <= 0.6:
                        b_found[k] += 1
                for g in got:
                    if np.min(np.linalg.norm(centres - g, axis=1)) > 1.0:
                        b_spur += 1
                        if args.show_spurious:
                            print(
                                f"  spurious at ({g[0]:.1f}, {g[1]:.1f}) seen from "
                                f"({x:.1f}, {y:.1f}, {math.degrees(yaw):.0f} deg)"
                            )
            views += args.views
            seen += b_seen
            found += b_found
            spurious += b_spur
            print(
                f"{name}: recall {b_found.sum():.0f}/{b_seen.sum():.0f}, "
                f"spurious {b_spur} in {args.views} views"
            )
    print("\nrecall by distance (m):")
    for k in range(len(BANDS) - 1):
        if seen[k]:
            print(
                f"  {BANDS[k]:4.0f}-{BANDS[k + 1]:<4.0f} "
                f"{found[k]:4.0f}/{seen[k]:<4.0f} {found[k] / seen[k]:6.1%}"
            )
    print(f"spurious detections: {spurious} in {views} views ({spurious / views:.3f} per view)")
    print(
        f"find_doors: p50 {np.median(ms):.0f} ms, "
        f"p95 {np.percentile(ms, 95):.0f} ms per {args.width}x{args.height} frame"
    )


EXAMPLES = (("sign_sparse_2", (15.0, 30.0, 180.0)), ("straight_office", (23.0, 0.0, 180.0)))


def write_examples(path: str, width: int, height: int, max_range: float) -> None:
    """Two views with each door found boxed (door height, its width along the wall) and its
    distance, scaled up 2x side by side."""
    import cv2

    from pmnav_bt.perception.depth import project
    from pmnav_bt.perception.door_sightings import DoorSeen

    panels = []
    for name, (x, y, yaw_deg) in EXAMPLES:
        with SimWorld(name) as world:
            base = SimBase(
                world, pose=Pose2D(x, y, math.radians(yaw_deg)), width=width, height=height
            )
            obs = base.observe()
            base.close()
        doors: list[DoorSeen] = find_doors(obs, surfaces(obs).wall, max_range)
        img = cv2.resize(obs.rgb, (2 * width, 2 * height), interpolation=cv2.INTER_NEAREST)
        img = np.ascontiguousarray(img[..., ::-1])
        for d in doors:
            along = np.array([math.cos(d.wall_angle), math.sin(d.wall_angle), 0.0])
            c = np.array([*d.centre, 0.0])
            z0, z1 = -obs.camera_height, 2.1 - obs.camera_height
            pts = np.array([c - along * d.width / 2, c + along * d.width / 2])
            corners = np.array([[*p[:2], z] for p in pts for z in (z0, z1)])
            uv = project(obs, corners) * 2.0
            if np.isnan(uv).any():
                continue
            (u0, v0), (u1, v1) = uv.min(axis=0), uv.max(axis=0)
            cv2.rectangle(img, (int(u0) - 2, int(v0)), (int(u1) + 2, int(v1)), (0, 200, 0), 2)
            cv2.putText(
                img,
                f"{math.hypot(*d.centre):.1f} m",
                (int(u0) - 10, int(v0) - 6),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.45,
                (0, 140, 0),
                1,
                cv2.LINE_AA,
            )
        cv2.putText(
            img,
            f"{name} ({x:g}, {y:g}, {yaw_deg:g} deg): {len(doors)} doors found",
            (8, 20),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.55,
            (0, 0, 0),
            1,
            cv2.LINE_AA,
        )
        panels.append(img)
    cv2.imwrite(path, np.hstack(panels))
    print(f"wrote {path}")


def building_heading(vis: Visibility, p) -> float:
    """The heading of the corridor segment a lattice point lies on."""
    return vis.pm.segments[p.segment - 1].heading


if __name__ == "__main__":
    main()
