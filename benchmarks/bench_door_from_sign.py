"""A read sign's door: how far from the true door each estimate is, per sign mounting.

Views of room sign plates are rendered (``sim.sign_views``) in worlds of the built-in
buildings, ``--seeds`` seeds each, in the ``--world`` preset (realistic: every building and
seed draws its signage, so plates hang beside the door on either side, on the leaf, above
the frame or as flags, and a third of the doors stand open). The plate's box is the
simulator's label of the sign (reading is ``bench_signs.py``'s business: this measures what
follows a read), its pose from depth (``depth.plate_pose``); each door estimator then places
the door from RGB-D alone:

- ``convention``: ``doors.door_from_sign``, the door ``grounder.sign_to_door`` beside the
  plate, the side from colour, else ``grounder.door_side``;
- ``scene``: ``door_scene.door_for_plate``, the door found along the plate's wall.

The error is the distance on the floor plane from the estimate's centre to the door's as
built (``SimWorld.doors``); a door within 0.5 m is found (the tree stops at the estimate and
success is 1 m from the door: an estimate within 0.5 m leaves the approach its slack).
Mounting is what the world built (an ``on_door`` plate of an open door hangs beside it),
told from the plate's and the door's places. CPU-ms is process time per estimate.

Run: python benchmarks/bench_door_from_sign.py [--seeds 4] [--views 12] [--world realistic]
     [--buildings all] [--seed-base 0]
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import numpy as np

from pmnav_bt.config import WorldConfig
from pmnav_bt.geometry import se2_apply
from pmnav_bt.map.catalogue import builtin_buildings
from pmnav_bt.perception.depth import plate_pose
from pmnav_bt.perception.door_scene import door_for_plate
from pmnav_bt.perception.doors import DoorLayout, door_from_sign
from pmnav_bt.seams import EntityKind
from pmnav_bt.sim.sign_views import (
    built_mounting,
    labelled_plate_box,
    sample_views,
)
from pmnav_bt.sim.world import SimWorld

FOUND_M = 0.5
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4, help="worlds per building")
    ap.add_argument("--seed-base", type=int, default=0)
    ap.add_argument("--views", type=int, default=12, help="views per world")
    ap.add_argument("--world", default="realistic", help="clean or realistic")
    ap.add_argument("--buildings", default="all")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    args = ap.parse_args()
    names = list(builtin_buildings()) if args.buildings == "all" else args.buildings.split(",")
    scene = WorldConfig(preset=args.world, people_per_100m=0.0)
    layout = DoorLayout()
    methods = {
        "convention": lambda obs, plate, box: door_from_sign(obs, plate, layout),
        "scene": lambda obs, plate, box: door_for_plate(obs, plate, box, layout),
    }
    errs: dict[tuple[str, str], list[float]] = defaultdict(list)
    ms: dict[str, list[float]] = defaultdict(list)
    states: dict[tuple[str, str], list[float]] = defaultdict(list)
    skipped = 0
    for name in names:
        for seed in range(args.seed_base, args.seed_base + args.seeds):
            with SimWorld(name, scene=scene, seed=seed) as world:
                views = sample_views(
                    world,
                    args.views,
                    width=args.width,
                    height=args.height,
                    distances=(1.5, 4.0),
                    seed=seed,
                    select=None,
                )
                for v in views:
                    if v.entity.kind != EntityKind.ROOM:
                        continue
                    rid = v.entity.id
                    obs = v.observation
                    box = labelled_plate_box(obs, rid)
                    plate = None if box is None else plate_pose(obs, box)
                    if plate is None:
                        skipped += 1
                        continue
                    door = world.doors[rid]
                    kind = built_mounting(world.signs[rid], door)
                    st = world.door_states.get(rid)
                    state = "open" if st and st.open else ("glass" if st and st.glass else "closed")
                    truth = np.asarray(door.centre, float)
                    here = (obs.pose.x, obs.pose.y, obs.pose.yaw)
                    for meth, fn in methods.items():
                        t0 = time.process_time()
                        est = fn(obs, plate, box)
                        ms[meth].append((time.process_time() - t0) * 1000.0)
                        e = float(np.linalg.norm(se2_apply(here, est.centre) - truth))
                        errs[(meth, kind)].append(e)
                        states[(meth, state)].append(e)
            print(f"{name} seed {seed}: done", flush=True)
    kinds = sorted({k for _, k in errs})
    print(f"\n{args.world} world, {args.width}x{args.height}; skipped (no plate pose): {skipped}")
    print("| mounting | n | convention: median error m, found | scene: median error m, found |")
    print("|---|---|---|---|")
    for rows, keys in ((errs, kinds), (states, sorted({k for _, k in states}))):
        for k in keys + ["all"]:
            cells = []
            n = 0
            for meth in methods:
                e = np.array(
                    [
                        x
                        for (m2, kk), xs in rows.items()
                        if m2 == meth and k in (kk, "all")
                        for x in xs
                    ]
                )
                n = len(e)
                cells.append(
                    f"{np.median(e):.2f}, {np.mean(e <= FOUND_M):.0%}" if n else "-"
                )
            print(f"| {k} | {n} | {cells[0]} | {cells[1]} |")
        print("|---|---|---|---|")
    for meth, xs in ms.items():
        print(f"{meth}: CPU p50 {np.median(xs):.1f} ms, p95 {np.percentile(xs, 95):.1f} ms")


if __name__ == "__main__":
    main()
