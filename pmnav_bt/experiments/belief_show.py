"""The corridor belief, run alone and seen: ``pmnav sim belief`` (or ``python -m
pmnav_bt.experiments.belief_show``).

Runs the localization subtree in the simulator from a start pose, as the Table 3 study
does (``localization_study.run_localization``), and draws the belief after each update
(``render/belief.py``): after each look round, after each drive (the depth readings and
doors seen on the way) and at the fix. One PNG a step and a contact sheet of all of them.

The default start is a scarce one of the sign-sparse building ``sign_sparse_2``: no sign
in reach there, so the belief has to drive and look several times before it fixes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import typer

if TYPE_CHECKING:  # the simulator and the drawing are imported when used: `pmnav` starts fast
    from pmnav_bt.config import Config
    from pmnav_bt.experiments.localization_study import LocStart
    from pmnav_bt.render.belief import BeliefStep

DEFAULT_BUILDING = "sign_sparse_2"


@dataclass
class BeliefWatch:
    """Called after every tick (``run_localization``'s ``watch``): keeps a copy of the
    belief each time it takes a look round in, the last one of each drive, and the fix."""

    steps: list[BeliefStep] = field(default_factory=list)
    _looks: int = 0
    _rays: int = 0
    _drive: tuple | None = None  # (belief, odom, truth, rays at its start) of a drive
    _last: object = None  # the belief last seen on the blackboard

    def __call__(self, ctx, body) -> None:
        import py_trees

        from pmnav_bt.behaviours.common import NAMESPACE
        from pmnav_bt.pose.belief import CorridorBelief
        from pmnav_bt.render.belief import BeliefStep

        store = py_trees.blackboard.Blackboard.storage
        belief = store.get(f"{NAMESPACE}/belief")
        odom, truth = ctx.base.pose(), body.pose()
        if belief is None:
            tf = store.get(f"{NAMESPACE}/map_T_odom")
            if tf is not None and (self._last is not None or not self.steps):
                # Fixed: the belief is let go (or was never needed: two signs at once).
                self._flush_drive()
                n, how = len(self.steps), "the pose is known (green)"
                if self._last is None:
                    self._last = CorridorBelief(ctx.pm, walls=ctx.walls)
                    how = "two signs read at once"
                self.steps.append(BeliefStep(f"{n}. fixed: {how}", self._last, odom, truth,
                                             tuple(tf)))  # fmt: skip
                self._last = None
            return
        self._last = belief
        if len(belief.rays) > self._rays:  # driving: keep the belief as it is now
            start = self._drive[3] if self._drive is not None else self._rays
            self._drive = (belief.fork(), odom, truth, start)
            self._rays = len(belief.rays)
        if len(belief.glimpses) > self._looks:
            self._flush_drive()
            self._looks = len(belief.glimpses)
            self.steps.append(BeliefStep(_look_title(len(self.steps), belief),
                                         belief.fork(), odom, truth))  # fmt: skip
            self._rays = len(belief.rays)

    def _flush_drive(self) -> None:
        from pmnav_bt.render.belief import BeliefStep

        if self._drive is None:
            return
        belief, odom, truth, start = self._drive
        was = self.steps[-1].odom if self.steps else odom
        driven = math.hypot(odom.x - was.x, odom.y - was.y)
        self.steps.append(BeliefStep(_drive_title(len(self.steps), belief, start, driven),
                                     belief, odom, truth))  # fmt: skip
        self._drive = None

    def finish(self) -> None:
        """After the run: a drive the run ended on."""
        self._flush_drive()


def _look_title(n: int, belief) -> str:
    g = belief.glimpses[-1]
    read = ", ".join(sorted(str(e.id) for e in g.seen)) or "no sign"
    named = f" (+{len(g.named)} cut by the border)" if g.named else ""
    doors = f"; {len(g.doors)} door(s) seen" if g.door_views else ""
    blocked = "; after a blocked drive" if g.blocked is not None else ""
    return f"{n}. look round {len(belief.glimpses)}: read {read}{named}{doors}{blocked}"


def _drive_title(n: int, belief, start: int, driven: float) -> str:
    rays = belief.rays[start:]
    doors = sum(len(r.doors) for r in rays)
    return (f"{n}. drive: {driven:.1f} m, {len(rays)} depth reading(s) ahead, "
            f"{doors} door sighting(s)")  # fmt: skip


def default_start(building: str, config: Config, seed: int = 0) -> LocStart:
    """The first scarce start of ``building`` (no sign in reach), as Table 3 draws them;
    else its first start of any class."""
    from pmnav_bt.experiments.localization_study import classified_starts
    from pmnav_bt.perception.read_range import landmark_ranges
    from pmnav_bt.pose.visibility import LandmarkDensity

    starts = classified_starts(building, 1, seed, landmark_ranges(config))
    scarce = [s for s in starts if s.density == LandmarkDensity.SCARCE.value]
    if not starts:
        raise typer.BadParameter(f"{building}: no start pose on its corridors")
    return (scarce or starts)[0]


def show_belief(start: LocStart, config: Config, out: Path) -> tuple[list[Path], Path, object]:
    """Run the localization from ``start`` and draw each step into ``out``: the step
    pictures, the contact sheet and the run's result."""
    from pmnav_bt.experiments.localization_study import run_localization
    from pmnav_bt.render.belief import render_sheet, render_step

    watch = BeliefWatch()
    result = run_localization(start, config, watch=watch)
    watch.finish()
    out.mkdir(parents=True, exist_ok=True)
    paths = [render_step(s, out / f"step_{i:02d}.png") for i, s in enumerate(watch.steps)]
    sheet = render_sheet(watch.steps, out / "steps.png") if watch.steps else None
    return paths, sheet, result


def belief(
    building: str = typer.Option(DEFAULT_BUILDING, "--building", help="A building file or name."),
    start: str | None = typer.Option(
        None, "--start", help="Start pose x,y,yaw_deg (default: a scarce Table 3 start)."
    ),
    seed: int = typer.Option(0, "--seed", help="Seeds the default start and the noise."),
    out: Path = typer.Option(Path("out/belief"), "--out", help="Folder for the pictures."),
    config: Path | None = typer.Option(None, "--config", help="A run config YAML."),
    overrides: list[str] | None = typer.Option(None, "--set", help="section.key=value."),
) -> None:
    """Localize from a start and draw the corridor belief after every look and drive."""
    from pmnav_bt.config import load_config
    from pmnav_bt.experiments.localization_study import LocStart
    from pmnav_bt.loading import check_output_dir
    from pmnav_bt.sim.poses import parse_pose

    cfg = load_config(config, overrides or [])
    check_output_dir(out)
    if start is None:
        loc = default_start(building, cfg, seed)
    else:
        p = parse_pose(start)
        loc = LocStart(building, p.x, p.y, p.yaw, "given", -1, seed)
    typer.echo(f"{building}: from ({loc.x:.1f}, {loc.y:.1f}, {math.degrees(loc.yaw):.0f} deg)")
    paths, sheet, result = show_belief(loc, cfg, out)
    ok = "fixed" if result.success else f"not fixed ({result.failure})"
    typer.echo(f"{ok} after {result.attempts} look(s) round, {result.driven:.1f} m driven")
    if sheet is None:
        typer.echo("the belief was never updated: nothing to draw")
    else:
        typer.echo(f"wrote {len(paths)} step pictures to {out}/step_*.png and the sheet {sheet}")


def main() -> None:
    typer.run(belief)


if __name__ == "__main__":
    main()
