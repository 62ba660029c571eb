"""Rendered candidate crops for the pictogram reader, labelled by the simulator.

The reader sees what the sign candidate finder proposes, so the data is made the same
way: a realistic world (``world.preset=realistic``: its own signage system per building
and seed, clutter, people, open doors, light, the camera's noise, exposure and blur) is
rendered from a view of one of its plates (1-6 m, 0-75 deg off the plate's normal); the
finder runs on the frame as the ``ocr`` grounder runs it (at 320 px, its boxes scaled to
a 640 px reading view, or on a 320 px frame read as it is), and each candidate's patch
(``pictograms.plate_patch``) is labelled from the segmentation:

- ``toilet``: most of the box is a toilet pictogram plate, and most of the plate in view
  is in the box;
- ``text``: the same for a room plate of text;
- ``background``: no sign pixel in the box at all;
- a box that cuts a plate, or holds a plate and much else: left out (it is neither).

Only worlds whose toilets carry pictograms are drawn; half their views are of those
plates. A run is a
list of (building, world seed) pairs; ``--split dev`` draws development buildings and
world seeds, ``--split heldout`` the held-out buildings (seeds 1000-1999) and world seeds
never used in training. Colour schemes named by ``HELDOUT_COLOURS`` are left out of the
development split altogether, so the held-out split also measures signage colours the
network never saw.

``--synthetic N`` writes N patches of plates drawn by the simulator's plate renderer
instead (``synthetic``: many more signage styles than rendered worlds give, seen as a
camera would), half toilet pictograms, half text plates.

Run: python -m pmnav_bt.experiments.pictogram_data --split dev --worlds 30 --views 20 --out d.npz
     python -m pmnav_bt.experiments.pictogram_data --split dev --synthetic 5000 --out s.npz
"""

from __future__ import annotations

import argparse
import math
import os
import random
import sys
import time
from dataclasses import replace

import cv2
import numpy as np
from shapely.geometry import Point

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.signage import PlateStyle
from pmnav_bt.perception.pictograms import CLASSES, plate_patch
from pmnav_bt.perception.signs import MIN_LINE_PX, SignReader
from pmnav_bt.seams import CameraIntrinsics
from pmnav_bt.sim.scene import scene_rng
from pmnav_bt.sim.scene.camera_effects import CameraEffects
from pmnav_bt.sim.scene.signage import COLOUR_SCHEMES, resolve_signage

KINDS = ("hospital", "school", "office")
DEV_BUILDING_SEEDS = range(1, 400)  # development seeds (catalogue.DEV_SEEDS: 0-999)
HELDOUT_BUILDING_SEEDS = range(1000, 1400)  # catalogue.HELDOUT_SEEDS
DEV_WORLD_SEEDS = range(0, 50)
HELDOUT_WORLD_SEEDS = range(500, 550)
HELDOUT_COLOURS = ("black_on_yellow", "white_on_green")  # never in the development split
COVER = 0.5  # a labelled box: this much of it the plate, and this much of the plate in it
MAX_YAW_RATE = 1.9  # rad/s: the fastest turn of the body (its frames blur the most)


def colour_of(style: PlateStyle) -> str:
    """The colour scheme of ``style`` by its name in ``COLOUR_SCHEMES``."""
    pair = (style.text_rgb, style.plate_rgb)
    return next((n for n, p in COLOUR_SCHEMES.items() if p == pair), "other")


def label_box(box, seg: np.ndarray, plates: dict[int, str]) -> str | None:
    """The class of a candidate ``box`` (module docstring); ``plates``: segmentation id ->
    "toilet" or "text" for the frame's room plates. None: a box left out."""
    x0, y0 = max(0, int(box[0])), max(0, int(box[1]))
    x1, y1 = min(seg.shape[1], int(math.ceil(box[2]))), min(seg.shape[0], int(math.ceil(box[3])))
    region = seg[y0:y1, x0:x1]
    if region.size == 0:
        return None
    ids, counts = np.unique(region, return_counts=True)
    sign_px = {int(i): int(c) for i, c in zip(ids, counts, strict=True) if int(i) in plates}
    if not sign_px:
        return "background" if not np.isin(region, list(plates)).any() else None
    best = max(sign_px, key=sign_px.get)
    in_view = int((seg == best).sum())
    if sign_px[best] >= COVER * region.size and sign_px[best] >= COVER * in_view:
        return plates[best]
    return None


def world_views(
    name: str, world_seed: int, views: int, rng: random.Random
) -> tuple[list[np.ndarray], list[int], list[tuple]]:
    """Labelled patches of ``views`` views of building ``name`` in its realistic world
    ``world_seed``: (patches, class indices, metadata rows)."""
    from pmnav_bt.sim.render import render_camera  # pybullet: only when rendering
    from pmnav_bt.sim.robot import CAMERA_HEIGHT, HFOV, RADIUS
    from pmnav_bt.sim.sign_views import view_pose
    from pmnav_bt.sim.world import SimWorld

    scene = WorldConfig(preset="realistic")
    world = SimWorld(name, scene=scene, seed=world_seed)
    try:
        signage = resolve_signage(world.building, scene.signage, world.rng("signage"))
        colour = colour_of(signage.style)
        camera = CameraEffects.of_world(world)
        picto = {rid for rid, st in signage.rooms.items() if st.pictogram}
        items = list(world.signs.items())
        toilets = [(rid, it) for rid, it in items if rid in picto]
        reader = SignReader()  # its candidate finder, as the grounder's (4 a frame)
        patches, labels, meta = [], [], []
        made = tries = 0
        while made < views and tries < 50 * views:
            tries += 1
            pool = toilets if rng.random() < 0.5 else items
            rid, item = pool[rng.randrange(len(pool))]
            d = rng.uniform(1.0, 6.0)
            a = rng.uniform(0.0, math.radians(75.0))
            room = max(0.0, HFOV / 2 - math.atan2(0.3, d) - math.radians(2))
            pose, _ = view_pose(item, d, a, rng.choice((-1, 1)), rng.uniform(-room, room))
            if not world.free_space.contains(Point(pose.x, pose.y).buffer(RADIUS + 0.05)):
                continue
            made += 1
            wide = rng.random() < 0.75  # most bodies read in a 640 px view
            w = 640 if wide else 320
            k = CameraIntrinsics.from_hfov(w, w * 3 // 4, HFOV)
            f = render_camera(world, pose.x, pose.y, pose.yaw, k, height=CAMERA_HEIGHT, depth=False)
            yaw_rate = rng.choice((0.0, 0.0, rng.uniform(-MAX_YAW_RATE, MAX_YAW_RATE)))
            rgb = camera.apply(f.rgb, yaw_rate=yaw_rate, fx=k.fx, key=(float(made), pose.x, pose.y))
            with world.lock:
                labels_now = dict(world.labels)
            plates = {}
            for i, lab in labels_now.items():
                if lab.startswith("sign:"):
                    plates[i] = "toilet" if lab[len("sign:"):] in picto else "text"
            if wide:
                frame = cv2.resize(rgb, (320, 240), interpolation=cv2.INTER_AREA)
                found = reader.candidates(frame, min_line_px=MIN_LINE_PX / 2)
                boxes = [(b[0] * 2, b[1] * 2, b[2] * 2, b[3] * 2) for b, _ in found]
            else:
                boxes = [b for b, _ in reader.candidates(rgb)]
            for box in boxes:
                lab = label_box(box, f.segmentation, plates)
                patch = plate_patch(rgb, box)
                if lab is None or patch is None:
                    continue
                patches.append(patch)
                labels.append(CLASSES.index(lab))
                meta.append((name, world_seed, colour, w, round(d, 2), round(math.degrees(a), 1)))
        return patches, labels, meta
    finally:
        world.close()


# -- plates drawn by the simulator's plate renderer, seen as the camera would ---------------

WALL_RGB = ((205, 208, 210), (226, 220, 204), (150, 156, 160), (232, 232, 228), (180, 170, 150))
TEXT_WORDS = ("Pharmacy", "Radiology", "Staff Room", "Store", "Meeting Room", "Office",
              "Library", "Classroom", "Cafe", "Cleaner", "Lift A", "Stairs", "Reception")


def synthetic_patch(rng: np.random.Generator, toilet: bool, skip_colours: tuple[str, ...]):
    """One patch of a plate drawn by the simulator's own renderer (``plates.make_plate``)
    in a style drawn as ``signage.draw_style`` draws a building's, seen 1-6 m away and
    0-75 deg off its normal by a 640 px camera: foreshortened, on a wall, dimmed or
    brightened, noisy, sometimes smeared; the candidate box around it off by up to a
    tenth. A toilet pictogram, or a room plate of text."""
    from pmnav_bt.sim.robot import HFOV  # pybullet: only when drawing
    from pmnav_bt.sim.scene.plates import make_plate
    from pmnav_bt.sim.scene.signage import draw_style

    while True:
        style = draw_style(rng)
        if colour_of(style) not in skip_colours:
            break
    if toilet:
        style = replace(style, pictogram="toilet")
    number = str(int(rng.integers(1, 400)))
    text = f"{number} {TEXT_WORDS[int(rng.integers(len(TEXT_WORDS)))]}"
    tex = make_plate(text, style)
    fx = 320.0 / math.tan(HFOV / 2)
    d, a = float(rng.uniform(1.0, 6.0)), float(rng.uniform(0.0, math.radians(75.0)))
    w_px = max(4.0, fx * tex.width_m * math.cos(a) / d)
    h_px = max(3.0, fx * tex.height_m / d)
    keystone = 1.0 + float(rng.uniform(-1, 1)) * math.sin(a) * tex.width_m / (2 * d)
    margin = int(max(8, 0.6 * h_px))
    W, H = int(w_px) + 2 * margin, int(h_px) + 2 * margin
    wall = np.array(WALL_RGB[int(rng.integers(len(WALL_RGB)))], np.float32)
    img = np.empty((H, W, 3), np.float32)
    img[:] = wall * float(rng.uniform(0.8, 1.1))
    size = (max(2, int(w_px)), max(2, int(h_px)))
    src = cv2.resize(tex.image, size, interpolation=cv2.INTER_AREA)
    sh, sw = src.shape[:2]
    x0, y0 = margin, margin
    dh = (keystone - 1.0) * h_px / 2
    quad = np.float32([[x0, y0 - dh], [x0 + w_px, y0 + dh], [x0 + w_px, y0 + h_px - dh],
                       [x0, y0 + h_px + dh]])
    m = cv2.getPerspectiveTransform(np.float32([[0, 0], [sw, 0], [sw, sh], [0, sh]]), quad)
    warped = cv2.warpPerspective(src, m, (W, H), flags=cv2.INTER_LINEAR)
    mask = cv2.warpPerspective(np.ones((sh, sw), np.float32), m, (W, H))[..., None]
    backing = np.array(style.plate_rgb, np.float32) * 0.6
    grown = cv2.dilate(mask, np.ones((3, 3), np.uint8))[..., None]
    img = img * (1 - grown) + backing * grown
    img = img * (1 - mask) + warped.astype(np.float32) * mask
    img *= float(rng.uniform(0.7, 1.25))  # the world's light and the camera's exposure
    if rng.random() < 0.25:
        k = int(rng.integers(2, 6))
        img = cv2.blur(img, (k, 1))
    img += rng.normal(0.0, 255 * 0.02, img.shape)
    img = np.clip(img + 0.5, 0, 255).astype(np.uint8)
    jit = rng.uniform(-0.1, 0.1, 4) * np.array([w_px, h_px, w_px, h_px])
    box = (x0 + jit[0], y0 - abs(dh) + jit[1], x0 + w_px + jit[2], y0 + h_px + abs(dh) + jit[3])
    return plate_patch(img, box)


def synthetic(n: int, seed: int, skip_colours: tuple[str, ...] = HELDOUT_COLOURS):
    """``n`` synthetic patches, half toilet pictograms and half text plates: (patches,
    class indices)."""
    rng = np.random.default_rng(seed)
    patches, labels = [], []
    while len(patches) < n:
        toilet = len(patches) % 2 == 0
        p = synthetic_patch(rng, toilet, skip_colours)
        if p is not None:
            patches.append(p)
            labels.append(CLASSES.index("toilet" if toilet else "text"))
    return np.stack(patches), np.array(labels, np.int64)


def draws_pictograms(name: str, world_seed: int, skip_colours: tuple[str, ...]) -> bool:
    """Whether building ``name``'s realistic world ``world_seed`` hangs toilet pictograms,
    in a colour scheme not in ``skip_colours`` (decided from the seed, nothing built)."""
    b = load_building(resolve_building_path(name))
    signage = resolve_signage(b, "random", scene_rng(world_seed, b.name, "signage"))
    if signage is None or colour_of(signage.style) in skip_colours:
        return False
    return any(st.pictogram for st in signage.rooms.values())


def pairs(split: str, n: int, seed: int) -> list[tuple[str, int]]:
    """``n`` (building, world seed) pairs of the split whose worlds hang toilet pictograms."""
    rng = random.Random(seed)
    bseeds = DEV_BUILDING_SEEDS if split == "dev" else HELDOUT_BUILDING_SEEDS
    wseeds = DEV_WORLD_SEEDS if split == "dev" else HELDOUT_WORLD_SEEDS
    skip = HELDOUT_COLOURS if split == "dev" else ()
    out: list[tuple[str, int]] = []
    while len(out) < n:
        name, ws = f"{rng.choice(KINDS)}_{rng.choice(bseeds)}", rng.choice(wseeds)
        if draws_pictograms(name, ws, skip):
            out.append((name, ws))
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--split", choices=("dev", "heldout"), required=True)
    ap.add_argument("--worlds", type=int, default=60)
    ap.add_argument("--views", type=int, default=40, help="views per world")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True, help=".npz to write (after every world)")
    ap.add_argument("--synthetic", type=int, default=0,
                    help="write this many synthetic patches instead (synthetic())")
    args = ap.parse_args(argv)
    if args.synthetic:
        sp, sl = synthetic(args.synthetic, args.seed)
        save(args.out, sp, sl, [("synthetic", i, "", 640, 0.0, 0.0) for i in range(len(sl))])
        return
    rng = random.Random(args.seed)
    patches, labels, meta = [], [], []
    t0 = time.time()
    for i, (name, ws) in enumerate(pairs(args.split, args.worlds, args.seed)):
        p, lab, m = world_views(name, ws, args.views, rng)
        patches += p
        labels += lab
        meta += m
        counts = np.bincount(labels, minlength=len(CLASSES))
        print(f"[{i + 1}/{args.worlds}] {name} seed {ws}: {len(p)} patches; total "
              f"{dict(zip(CLASSES, counts.tolist(), strict=True))} ({time.time() - t0:.0f} s)",
              file=sys.stderr, flush=True)
        if patches:  # after every world, so a long run can be used while it goes on
            save(args.out, np.stack(patches), np.array(labels, np.int64), meta)


def save(path: str, patches: np.ndarray, labels: np.ndarray, meta: list[tuple]) -> None:
    tmp = f"{path}.tmp.npz"
    np.savez_compressed(tmp, patches=patches, labels=labels, meta=np.array(meta, dtype=object))
    os.replace(tmp, path)


if __name__ == "__main__":
    main()
