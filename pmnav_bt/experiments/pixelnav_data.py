"""Training data: seeded expert rollouts to goal pixels, in the simulator, as shards.

An episode starts at a random free pose of a *generated* building (the built-in buildings
are the evaluation set and never appear here), takes the first frame, picks a goal in it:
a door's or a sign's mask centre, or a floor pixel, whose point lies 1-5 m away; then a
shortest-path expert (the geodesic field of ``pmnav_bt.eval.geodesic`` on the local floor)
drives there with the discrete actions (stop, forward 0.25 m, turn 30 deg) and stops
inside ``stop_radius`` of the goal point. With probability ``noise`` a random move is
carried out instead of the expert's (its label stays the expert's), so the data shows how
to recover from a detour.

Recorded per step: the small frame, the expert action, the temporal distance (steps left
to the stop), and the goal point's pixel in that frame (goal tracking). Per episode: the
goal pixel and goal mask in the first frame, the goal kind, the goal and start in the map.

A shard is one ``.npz`` of ``episodes_per_shard`` episodes on one building, named by its
index and written atomically, so an interrupted ``gen`` resumes at the first missing shard,
and shard ``i`` of a seed is the same file on every run.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import shapely
from pydantic import BaseModel, ConfigDict, Field

from pmnav_bt.errors import PmNavError
from pmnav_bt.pixelnav.dataset import (
    ACTIONS,
    FORWARD,
    KINDS,
    LEFT,
    MAX_STEPS,
    RIGHT,
    STOP,
    Episode,
    pack,
    shard_path,
)
from pmnav_bt.pixelnav.frames import HFOV, back_project, project, shrink
from pmnav_bt.seams import (
    CAMERA_HEIGHT_M,
    CREATE3_RADIUS_M,
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    CameraIntrinsics,
    Pose2D,
)

# Building seeds: training shards draw from the first range, held-out evaluation from
# the second; neither is a built-in building.
TRAIN_BUILDING_SEEDS = (100_000, 200_000)
HELDOUT_BUILDING_SEEDS = (900_000, 1_000_000)


class DataGenError(PmNavError):
    """A data folder that does not match the requested generation config."""


class DataConfig(BaseModel):
    """What ``pmnav pixelnav gen`` makes."""

    model_config = ConfigDict(extra="forbid")

    seed: int = Field(0, ge=0, description="shard i of a seed is always the same file")
    shards: int = Field(40, ge=1, le=100_000)
    episodes_per_shard: int = Field(50, ge=1, le=10_000)
    width: int = Field(64, ge=16, le=640, description="policy frame width (px)")
    height: int = Field(48, ge=12, le=480, description="policy frame height (px)")
    render_scale: int = Field(2, ge=1, le=8, description="first frame (goal choice): times larger")
    min_dist: float = Field(1.0, gt=0.0, description="goal at least this far (m)")
    max_dist: float = Field(5.0, gt=0.0, description="goal at most this far (m)")
    stop_radius: float = Field(0.5, gt=0.0, description="the expert stops this close (m)")
    noise: float = Field(0.1, ge=0.0, le=1.0, description="chance of a random move")
    min_mask_px: int = Field(30, ge=1, description="door/sign pixels (render size) to count")
    heldout: bool = Field(False, description="held-out buildings (evaluation), not training")


def building_seed(cfg: DataConfig, shard: int) -> int:
    """The generated building of ``shard`` (the same for a seed, disjoint train/held-out)."""
    lo, hi = HELDOUT_BUILDING_SEEDS if cfg.heldout else TRAIN_BUILDING_SEEDS
    rng = np.random.default_rng([cfg.seed, shard, 7])
    return int(rng.integers(lo, hi))


def make_building(seed: int):
    """A generated building of varied size, corridor width and loops, from its seed (the
    first valid draw of a few: a wide corridor can leave a landmark out of reach)."""
    from pmnav_bt.map.generate import generate_building

    rng = np.random.default_rng([seed, 11])
    for _ in range(20):
        try:
            return generate_building(
                n_rooms=int(rng.integers(6, 17)),
                seed=seed,
                spacing=float(rng.uniform(14.0, 24.0)),
                loop_fraction=float(rng.uniform(0.0, 0.3)),
                corridor_width=float(rng.uniform(1.8, 3.0)),
                n_landmarks=int(rng.integers(1, 5)),
                name=f"pixelnav_{seed}",
            )
        except PmNavError:
            continue
    raise DataGenError(f"building seed {seed}: no valid generated building in 20 draws")


class Roller:
    """Rollouts in one world: a small camera, the expert, the recording."""

    def __init__(self, world, cfg: DataConfig):
        from pmnav_bt.sim.clock import SimClock
        from pmnav_bt.sim.robot import COLLISION_HEIGHT, SimBase

        self.world, self.cfg = world, cfg
        s = cfg.render_scale
        self.base = SimBase(
            world, SimClock(tick=0.05), width=cfg.width, height=cfg.height, hfov=HFOV
        )
        self.k_small = self.base.intrinsics
        self.k_big = CameraIntrinsics.from_hfov(cfg.width * s, cfg.height * s, HFOV)
        self.floor = world.floor_space()
        self.obstacles = world.obstacle_footprints(COLLISION_HEIGHT)
        self.starts = self.floor.buffer(-(CREATE3_RADIUS_M + 0.15))
        for o in self.obstacles:
            self.starts = self.starts.difference(o.buffer(CREATE3_RADIUS_M + 0.15))

    def random_start(self, rng: np.random.Generator) -> Pose2D:
        x0, y0, x1, y1 = self.starts.bounds
        while True:
            x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
            if shapely.contains_xy(self.starts, x, y):
                return Pose2D(float(x), float(y), float(rng.uniform(-math.pi, math.pi)))

    def first_frame(self, pose: Pose2D):
        """The first frame at ``render_scale`` times the policy's size, with depth and labels."""
        from pmnav_bt.sim.render import render_camera

        return render_camera(self.world, pose.x, pose.y, pose.yaw, self.k_big)

    def pick_goal(self, pose: Pose2D, frame, rng: np.random.Generator):
        """(kind, map point, render-size mask) of a goal in the frame 1-5 m away, or None.

        Doors and signs come first when the frame has them (the tree's goals), floor
        points otherwise and in a quarter of the episodes."""
        cfg, k = self.cfg, self.k_big
        seg, depth = frame.segmentation, frame.depth
        labels = self.world.labels
        by_kind: dict[str, list[np.ndarray]] = {"door": [], "sign": [], "floor": []}
        for lid, label in labels.items():
            kind = label.partition(":")[0]
            if kind in ("door", "sign"):
                m = seg == lid
                if m.sum() >= cfg.min_mask_px:
                    by_kind[kind].append(m)
        floor = seg == next((i for i, lab in labels.items() if lab == "floor"), -1)
        if floor.any():
            by_kind["floor"].append(floor)
        kinds = [kd for kd in ("door", "sign") if by_kind[kd]]
        rng.shuffle(kinds)
        if by_kind["floor"]:
            kinds.insert(0 if rng.random() < 0.25 else len(kinds), "floor")
        for kind in kinds:
            found = []
            for m in by_kind[kind]:
                ys, xs = np.nonzero(m)
                if kind == "floor":  # a few random floor pixels
                    for i in rng.integers(len(xs), size=8):
                        mask = np.zeros_like(m)
                        mask[max(0, ys[i] - 2) : ys[i] + 3, max(0, xs[i] - 2) : xs[i] + 3] = True
                        found.append(
                            (float(xs[i]), float(ys[i]), float(depth[ys[i], xs[i]]), mask & m)
                        )
                else:  # the grounder's goal pixel: the mask centre
                    found.append(
                        (float(xs.mean()), float(ys.mean()), float(np.median(depth[m])), m)
                    )
            fits = []
            for u, v, z, mask in found:
                pt = back_project(pose, k, u, v, z, CAMERA_HEIGHT_M)
                if kind == "floor":
                    pt[2] = 0.0
                if cfg.min_dist <= math.hypot(pt[0] - pose.x, pt[1] - pose.y) <= cfg.max_dist:
                    fits.append((pt, mask))
            if fits:
                pt, mask = fits[int(rng.integers(len(fits)))]
                return KINDS.index(kind), pt, mask
        return None

    def field(self, start: Pose2D, goal: np.ndarray):
        """The expert's distance field on the floor around start and goal (None: unreachable)."""
        from pmnav_bt.eval.geodesic import GeodesicError, GeodesicField

        pad = 4.0
        box = shapely.box(
            min(start.x, goal[0]) - pad,
            min(start.y, goal[1]) - pad,
            max(start.x, goal[0]) + pad,
            max(start.y, goal[1]) + pad,
        )
        near = [o for o in self.obstacles if o.intersects(box)]
        try:
            f = GeodesicField(
                self.floor.intersection(box),
                goal[:2],
                self.cfg.stop_radius,
                robot_radius=CREATE3_RADIUS_M + 0.05,
                obstacles=near,
            )
        except GeodesicError:
            return None
        return f if f.drivable_at((start.x, start.y)) else None

    def expert(self, f, pose: Pose2D) -> int:
        """The shortest-path action: stop in the region, else forward when the step ahead
        is (nearly) the best of the twelve headings, else turn towards the best."""
        d0 = f.distance((pose.x, pose.y))
        if d0 <= 0.0:
            return STOP
        best_k, best = 0, math.inf
        ahead = math.inf
        for kk in range(12):
            yaw = pose.yaw + kk * TURN_STEP_RAD
            xy = (pose.x + FORWARD_STEP_M * math.cos(yaw), pose.y + FORWARD_STEP_M * math.sin(yaw))
            d = f.distance(xy) if f.drivable_at(xy) else math.inf
            if kk == 0:
                ahead = d
            if d < best - 1e-9:
                best_k, best = kk, d
        if math.isfinite(ahead) and ahead <= best + 0.02 and ahead < d0 - 0.05:
            return FORWARD
        if best_k == 0:  # nothing ahead improves enough: turn to the better side
            best_k = 1
        return LEFT if best_k <= 6 else RIGHT

    def episode(self, rng: np.random.Generator) -> Episode | None:
        """One rollout from a random start, or None when no goal fits or the expert fails."""
        cfg, base = self.cfg, self.base
        start = self.random_start(rng)
        base.set_pose(start)
        first = self.first_frame(start)
        goal = self.pick_goal(start, first, rng)
        if goal is None:
            return None
        kind, pt, mask = goal
        f = self.field(start, pt)
        if f is None or not math.isfinite(f.distance((start.x, start.y))):
            return None
        frames, actions, track, valid = [], [], [], []
        rgb = first.rgb
        for _ in range(MAX_STEPS):
            pose = base.pose()
            frames.append(shrink(rgb, cfg.width, cfg.height))
            u, v, zc = project(pose, self.k_small, pt, CAMERA_HEIGHT_M)
            ok = zc > 0.05
            track.append((u / cfg.width, v / cfg.height) if ok else (0.0, 0.0))
            valid.append(ok)
            a = self.expert(f, pose)
            actions.append(a)
            if a == STOP:
                break
            done = a
            if rng.random() < cfg.noise:
                done = int(rng.integers(1, 4))
            base.execute(ACTIONS[done])
            rgb = base.render_view(0.0, depth=False, segmentation=False).rgb
        else:
            return None  # no stop within the budget
        n = len(actions)
        u0, v0, _ = project(start, self.k_small, pt, CAMERA_HEIGHT_M)
        small_mask = shrink(mask.astype(np.uint8) * 255, cfg.width, cfg.height) > 0
        return Episode(
            frames=np.stack(frames),
            actions=np.array(actions, np.int8),
            tdist=np.arange(n - 1, -1, -1, dtype=np.int16),
            track=np.clip(np.array(track, np.float32), -1.0, 2.0),
            track_valid=np.array(valid, bool),
            goal_px=np.array([u0, v0], np.float32),
            goal_mask=small_mask,
            kind=kind,
            goal=pt.astype(np.float32),
            start=np.array([start.x, start.y, start.yaw], np.float32),
            geodesic=float(f.distance((start.x, start.y))),
        )


def generate_shard(cfg: DataConfig, shard: int) -> dict[str, np.ndarray]:
    """The arrays of shard ``shard``: ``episodes_per_shard`` rollouts on its building."""
    from pmnav_bt.sim.world import SimWorld

    bseed = building_seed(cfg, shard)
    rng = np.random.default_rng([cfg.seed, shard])
    eps: list[Episode] = []
    tries = 0
    with SimWorld(make_building(bseed)) as world:
        roller = Roller(world, cfg)
        while len(eps) < cfg.episodes_per_shard:
            tries += 1
            if tries > 50 * cfg.episodes_per_shard:
                raise DataGenError(f"shard {shard}: building {bseed} yields too few goals")
            ep = roller.episode(rng)
            if ep is not None:
                eps.append(ep)
        roller.base.close()
    return pack(eps, bseed)


def generate(cfg: DataConfig, out: str | Path, progress: bool = True) -> list[Path]:
    """Write every missing shard of ``cfg`` to ``out`` (resumable); the shard paths."""
    from tqdm import tqdm

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    meta = out / "config.json"
    want = cfg.model_dump()
    if meta.is_file():
        have = json.loads(meta.read_text(encoding="utf-8"))
        if {k: v for k, v in have.items() if k != "shards"} != {
            k: v for k, v in want.items() if k != "shards"
        }:
            raise DataGenError(
                f"{meta}: written with another config ({have}); use a new folder or the same "
                "settings (only --shards may grow)"
            )
    meta.write_text(json.dumps(want, indent=2), encoding="utf-8")
    paths = [shard_path(out, i) for i in range(cfg.shards)]
    todo = [i for i, path in enumerate(paths) if not path.is_file()]
    bar = tqdm(total=cfg.shards, initial=cfg.shards - len(todo), unit="shard", disable=not progress)
    for i in todo:
        arrays = generate_shard(cfg, i)
        tmp = paths[i].with_name(f".{paths[i].stem}.{os.getpid()}.tmp.npz")
        np.savez_compressed(tmp, **arrays)
        tmp.replace(paths[i])
        bar.set_postfix(steps=len(arrays["actions"]))
        bar.update(1)
    bar.close()
    return paths
