"""What the robot sees in a world preset, many worlds at once: ``pmnav sim sheet``.

Builds the world of each (building, seed) as an episode of that seed would (the config's
``world`` section: ``--set world.preset=realistic``), stands the robot's camera in a
corridor a few metres from a door drawn from the seed, looking along the wall at it (where
a person walking the corridor sees door signs), and lays the first-person views out on one
contact sheet, each captioned with its building and seed. It is how a person judges
whether a preset looks like a hospital, a school or an office.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import typer

if TYPE_CHECKING:  # the simulator is imported when used: `pmnav` starts fast
    from pmnav_bt.config import Config
    from pmnav_bt.seams import Pose2D
    from pmnav_bt.sim.world import SimWorld

VIEW_DISTANCES_M = (2.5, 3.5, 4.5)  # along the wall from the door
VIEW_OUT_M = 0.9  # out from the wall
VIEW_TOWARDS_WALL_RAD = math.radians(20.0)  # the camera turned from the corridor to the wall


def door_view_pose(world: SimWorld, rng: np.random.Generator) -> Pose2D:
    """A camera pose in the corridor a few metres from a door drawn by ``rng``, looking
    along the wall towards it; the world's start pose when no door has room in front."""
    from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D

    doors = list(world.doors.values())
    for k in rng.permutation(len(doors)):
        d = doors[int(k)]
        c, n = np.asarray(d.centre), np.asarray(d.normal)
        along = np.array([n[1], -n[0]])
        for dist in rng.permutation(VIEW_DISTANCES_M):
            for side in rng.permutation([-1.0, 1.0]):
                xy = c + n * VIEW_OUT_M + along * side * dist
                if world.clearance(float(xy[0]), float(xy[1]), CREATE3_RADIUS_M) < 0.0:
                    continue
                look = -along * side  # back along the wall, towards the door
                yaw = math.atan2(look[1], look[0])
                turn = VIEW_TOWARDS_WALL_RAD * np.sign(look[0] * -n[1] + look[1] * n[0])
                return Pose2D(float(xy[0]), float(xy[1]), yaw + float(turn))
    return world.start_pose()


def world_view(building: str, seed: int, config: Config) -> np.ndarray:
    """The first-person RGB of the world of ``building`` in the episode of ``seed``."""
    from pmnav_bt.sim.odometry import simulated_robot
    from pmnav_bt.sim.world import SimWorld

    with SimWorld(building, walls=config.sim.walls, scene=config.world, seed=seed) as world:
        pose = door_view_pose(world, world.rng("sheet"))
        body, _ = simulated_robot(world, config.sim, pose, seed)
        return body.observe().rgb


def caption(image: np.ndarray, text: str) -> np.ndarray:
    """``image`` with ``text`` on a dark band along its bottom edge."""
    import cv2

    out = image.copy()
    h = out.shape[0]
    band = max(14, h // 14)
    out[h - band :] = (out[h - band :] * 0.35).astype(np.uint8)
    scale = band / 30.0
    cv2.putText(out, text, (4, h - band // 4), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255),
                1, cv2.LINE_AA)  # fmt: skip
    return out


def tile(images: list[np.ndarray], cols: int) -> np.ndarray:
    """Images of one size laid out row by row, ``cols`` to a row (black where none)."""
    h, w = images[0].shape[:2]
    rows = math.ceil(len(images) / cols)
    sheet = np.zeros((rows * h, cols * w, 3), np.uint8)
    for k, img in enumerate(images):
        r, c = divmod(k, cols)
        sheet[r * h : (r + 1) * h, c * w : (c + 1) * w] = img
    return sheet


def sheet(
    building: str = typer.Option(
        "all", "--building", help="Buildings, as for sim eval (all, names, FAMILY:N), in turn."
    ),
    seeds: int = typer.Option(16, "--seeds", min=1, max=256, help="Views: seeds 0..N-1."),
    cols: int = typer.Option(4, "--cols", min=1, max=16, help="Views per row."),
    out: Path = typer.Option(Path("world_sheet.png"), "--out", help="The sheet (PNG)."),
    config: Path | None = typer.Option(None, "--config", help="A run config YAML."),
    overrides: list[str] | None = typer.Option(None, "--set", help="section.key=value."),
) -> None:
    """A contact sheet of first-person views of the worlds episodes of seeds 0..N-1 drive
    in, cycling through the buildings (`--set world.preset=realistic`)."""
    from pmnav_bt.experiments.options import building_names, run_config
    from pmnav_bt.loading import check_output_file
    from pmnav_bt.sim.textures import write_png

    cfg = run_config(config, overrides)
    names = building_names(building)
    check_output_file(out)
    views = []
    for seed in range(seeds):
        name = names[seed % len(names)]
        views.append(caption(world_view(name, seed, cfg), f"{name}  seed {seed}"))
    path = write_png(tile(views, min(cols, len(views))), out)
    typer.echo(f"wrote {path}: {len(views)} views, world preset {cfg.world.preset}")
