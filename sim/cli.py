"""``pmnav sim``: look at a simulated building (top-down plan and a first-person view)."""

from __future__ import annotations

import math
import time
from pathlib import Path

import typer

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import Pose2D

app = typer.Typer(
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="The pybullet simulator: build a world from a building file and look at it.",
)


@app.callback()
def _group() -> None:
    """The pybullet simulator: build a world from a building file and look at it."""


class PoseError(PmNavError):
    """A --pose value that is not x,y,yaw_deg."""


def parse_pose(text: str) -> Pose2D:
    """'x,y,yaw_deg' (metres, degrees) -> Pose2D (radians)."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, yaw_deg = (float(v) for v in parts)
    except ValueError:
        raise PoseError(
            f"--pose {text!r}: expected three numbers 'x,y,yaw_deg', e.g. --pose 0,30,-90"
        ) from None
    return Pose2D(x, y, math.radians(yaw_deg))


@app.command()
def show(
    building: str = typer.Argument(..., help="A building file (YAML) or a built-in name."),
    out: Path = typer.Option(Path("sim_show"), "--out", help="Folder for the images."),
    pose: str | None = typer.Option(
        None, "--pose", help="Camera pose x,y,yaw_deg (default: the start, along its corridor)."
    ),
    width: int = typer.Option(640, "--width", min=16, help="Image width, pixels."),
    height: int = typer.Option(480, "--height", min=16, help="Image height, pixels."),
    gui: bool = typer.Option(False, "--gui", help="Also open the pybullet GUI (needs a display)."),
) -> None:
    """Write a top-down plan and the first-person RGB, depth and segmentation views."""
    from pmnav_bt.sim.render import (
        annotate_labels,
        colorize_depth,
        colorize_segmentation,
        draw_top_down,
    )
    from pmnav_bt.sim.robot import SimBase
    from pmnav_bt.sim.textures import write_png
    from pmnav_bt.sim.world import SimWorld

    start = parse_pose(pose) if pose is not None else None
    with SimWorld(building, gui=gui) as world:
        base = SimBase(world, pose=start, width=width, height=height)
        q = base.pose()
        obs = base.observe()
        name = world.building.name
        out.mkdir(parents=True, exist_ok=True)
        files = {
            f"{name}_top_down.png": draw_top_down(world, q),
            f"{name}_view_rgb.png": obs.rgb,
            f"{name}_view_depth.png": colorize_depth(obs.depth),
            f"{name}_view_seg.png": annotate_labels(
                colorize_segmentation(obs.segmentation, obs.labels), obs.segmentation, obs.labels
            ),
        }
        for fname, img in files.items():
            typer.echo(f"wrote {write_png(img, out / fname)}")
        seen = sorted({obs.labels[int(i)] for i in set(obs.segmentation.ravel().tolist())})
        typer.echo(
            f"pose x={q.x:.2f} y={q.y:.2f} yaw={math.degrees(q.yaw):.0f} deg; sees: "
            + ", ".join(seen)
        )
        if gui:
            typer.echo("GUI open; close its window (or Ctrl-C) to quit")
            _hold_gui(world)


def _hold_gui(world) -> None:  # pragma: no cover - needs a display
    import pybullet as p

    try:
        while True:
            with world.lock:
                if not p.isConnected(physicsClientId=world.client):
                    break
            time.sleep(0.1)
    except KeyboardInterrupt:
        pass
