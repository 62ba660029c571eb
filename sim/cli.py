"""``pmnav sim``: look at a simulated building (top-down plan and a first-person view)."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import typer

from pmnav_bt import cli_values
from pmnav_bt.errors import PmNavError
from pmnav_bt.loading import check_output_dir, check_output_file, safe_filename
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
    """'x,y,yaw_deg' (metres, degrees) -> Pose2D (radians); finite and in range."""
    from pmnav_bt.cli_values import CliValueError, parse_pose_text

    try:
        x, y, yaw_deg = parse_pose_text(text, "--pose")
    except CliValueError as err:
        raise PoseError(str(err)) from None
    return Pose2D(x, y, math.radians(yaw_deg))


@app.command()
def show(
    building: str = typer.Argument(..., help="A building file (YAML) or a built-in name."),
    out: Path = typer.Option(Path("sim_show"), "--out", help="Folder for the images."),
    pose: str | None = typer.Option(
        None, "--pose", help="Camera pose x,y,yaw_deg (default: the start, along its corridor)."
    ),
    width: int = typer.Option(640, "--width", min=16, max=4096, help="Image width, pixels."),
    height: int = typer.Option(480, "--height", min=16, max=4096, help="Image height, pixels."),
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
    check_output_dir(out)
    with SimWorld(building, gui=gui) as world:
        base = SimBase(world, pose=start, width=width, height=height)
        q = base.pose()
        obs = base.observe()
        name = safe_filename(world.building.name)
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
    from pmnav_bt.sim._pybullet import p

    try:
        while True:
            with world.lock:
                if not p.isConnected(physicsClientId=world.client):
                    break
            time.sleep(0.1)
    except KeyboardInterrupt:
        pass


TIER_NAMES = ("easy", "medium", "hard")


def _tiers(tier: str) -> list[str]:
    if tier == "all":
        return list(TIER_NAMES)
    if tier not in TIER_NAMES:
        raise PmNavError(f"--tier {tier!r}: choose easy, medium, hard or all")
    return [tier]


def _buildings(building: str) -> list[str]:
    from pmnav_bt.map.building import builtin_buildings

    if building != "all":
        return [b.strip() for b in building.split(",") if b.strip()]
    six = ["straight_office", "l_hospital", "t_school", "u_office", "loop_hospital", "ring_school"]
    return [b for b in six if b in builtin_buildings()]


def _config(config: Path | None, overrides: list[str] | None):
    from pmnav_bt.config import load_config

    return load_config(config, overrides or [])


CONFIG_OPT = typer.Option(None, "--config", help="A run config YAML (see docs/config.md).")
SET_OPT = typer.Option(None, "--set", help="Override a config value: section.key=value.")


@app.command()
def episodes(
    building: str = typer.Argument(..., help="A building file or built-in name."),
    tier: str = typer.Option("easy", "--tier", help="easy, medium, hard or all."),
    n: int = typer.Option(20, "-n", min=1, help="Episodes per tier."),
    seed: int = typer.Option(0, "--seed"),
    out: Path | None = typer.Option(None, "--out", help="JSON file (default: print)."),
) -> None:
    """Generate seeded episodes of a tier and save them as JSON."""
    from pmnav_bt.sim.episodes import generate_episodes, save_episodes, tier_definition

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    if out is None:
        out = Path(f"{safe_filename(Path(building).stem)}_{safe_filename(tier)}_episodes.json")
    check_output_file(out, "--out", (".json",))
    eps = []
    for t in _tiers(tier):
        eps += generate_episodes(building, t, n, seed=seed)
    save_episodes(eps, out)
    typer.echo(tier_definition())
    typer.echo(f"wrote {len(eps)} episodes to {out}")


@app.command()
def run(
    building: str = typer.Option("fig2_hospital", "--building", help="A building or built-in."),
    goal: str = typer.Option(..., "--goal", help="The goal room: ID, name or alias."),
    start: str | None = typer.Option(
        None, "--start", help="Start: a segment, waypoint, or pose 'x,y,yaw_deg' (default: start)."
    ),
    episode_file: Path | None = typer.Option(
        None, "--episodes", help="Run an episode from a JSON file instead (with --index)."
    ),
    index: int = typer.Option(0, "--index", help="Which episode of --episodes."),
    seed: int = typer.Option(0, "--seed"),
    out: Path = typer.Option(Path("out/run"), "--out", help="Folder for the log and the plot."),
    show_tree: bool = typer.Option(False, "--show-tree", help="Show the live tree while it runs."),
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Run one PM-Nav episode and print its result; write the tree log and trajectory plot."""
    from pmnav_bt.experiments.evaluation import VARIANT_NAMES, custom_episode, run_episode

    cli_values.seed(seed)
    cli_values.index(index)
    cfg = _config(config, overrides)
    check_output_dir(out)
    if episode_file is not None:
        from pmnav_bt.sim.episodes import load_episodes

        eps = load_episodes(episode_file)
        if not 0 <= index < len(eps):
            raise PmNavError(f"--index {index}: {episode_file} has {len(eps)} episodes")
        ep = eps[index]
    else:
        ep = custom_episode(building, goal, start, seed)
    live = None
    if show_tree:
        from pmnav_bt.trees.live import LiveTree

        live = LiveTree()
    typer.echo(
        f"{VARIANT_NAMES[cfg.tree.variant]} in {ep.building}: {ep.id} ({ep.tier}), "
        f"start ({ep.start_x:.1f}, {ep.start_y:.1f}, {math.degrees(ep.start_yaw):.0f} deg), "
        f"shortest path {ep.geodesic_length:.1f} m"
    )
    if live is not None:
        with live:
            r = run_episode(ep, cfg, out_dir=out, on_tick=live)
    else:
        r = run_episode(ep, cfg, out_dir=out)
    res = r.result
    typer.echo(
        f"{'SUCCESS' if res.success else 'FAILURE'}: SPL {res.spl:.3f}, {res.steps} actions, "
        f"{res.path_length:.1f} m driven, {res.collisions} collisions, stopped "
        f"{res.distance_to_goal:.2f} m from the door, {res.wall_time:.1f} s wall"
    )
    if res.failure_reason:
        typer.echo(f"reason: {res.failure_reason}")
    typer.echo(f"tree log: {r.tree_log}\ntrajectory plot: {r.plot}")
    if not res.success:
        raise typer.Exit(1)


@app.command("eval")
def eval_(
    building: str = typer.Option("all", "--building", help="Comma-separated buildings, or all."),
    tier: str = typer.Option("all", "--tier", help="easy, medium, hard or all."),
    n: int = typer.Option(20, "-n", min=1, help="Episodes per tier per building."),
    seed: int = typer.Option(0, "--seed"),
    variants: str = typer.Option("pmnav,coarse_only", "--variants", help="Tree variants."),
    jobs: int | None = typer.Option(
        None, "--jobs", help="Episodes run in parallel [default: 2, at most the CPUs]."
    ),
    out: Path = typer.Option(Path("out/eval"), "--out", help="Folder for results.json/.md."),
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Run many episodes and print SR/SPL per tier for each tree variant (paper Table 1)."""
    from rich.progress import Progress

    from pmnav_bt.experiments.evaluation import (
        comparison_markdown,
        episodes_for,
        evaluate,
        save_evaluation,
        variant_configs,
    )
    from pmnav_bt.interrupts import Interrupted, JsonlAppender, stop_signals
    from pmnav_bt.sim.episodes import tier_definition

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    jobs = cli_values.jobs(jobs) if jobs is not None else min(2, cli_values.cpu_count())
    cfg = _config(config, overrides)
    check_output_dir(out)
    names = [v.strip() for v in variants.split(",") if v.strip()]
    configs = variant_configs(cfg, names)
    eps, notes = episodes_for(_buildings(building), _tiers(tier), n, seed)
    for note in notes:
        typer.echo(f"note: {note}", err=True)
    if not eps:
        raise PmNavError("no episodes to run")
    total = len(eps) * len(configs)
    finished: dict = {}
    with JsonlAppender(out / "results.jsonl") as log, stop_signals():
        save = lambda name, r: log.write({"variant": name, **r.to_dict()})  # noqa: E731
        try:
            if sys.stderr.isatty():
                with Progress(transient=False) as bar:
                    task = bar.add_task("episodes", total=total)
                    results = evaluate(
                        eps,
                        configs,
                        jobs=jobs,
                        progress=lambda name, done, _: bar.update(task, completed=done),
                        on_result=save,
                        finished=finished,
                    )
            else:  # a log: a line every tenth of the way
                step = max(1, total // 10)

                def report(name: str, done: int, _total: int) -> None:
                    if done % step == 0 or done == total:
                        typer.echo(f"{done}/{total} episodes ({name})", err=True)

                results = evaluate(
                    eps, configs, jobs=jobs, progress=report, on_result=save, finished=finished
                )
        except Interrupted as stop:
            kept = {k: v for k, v in finished.items() if v}
            if kept:
                save_evaluation(kept, out, f"# PM-Nav evaluation (stopped by {stop.signame})")
            typer.echo(
                f"pmnav: stopped by {stop.signame} after {log.count} of {total} episodes; "
                f"finished ones are in {out / 'results.jsonl'}",
                err=True,
            )
            raise typer.Exit(stop.exit_code) from None
    g = cfg.grounder
    header = (
        f"# PM-Nav evaluation\n\nbuildings: {building}; tiers: {tier}; {n} per tier per "
        f"building; seed {seed}; grounder {g.backend} (miss {g.miss_rate:.0%}, false positives "
        f"{g.false_positive_rate:.0%}); odometry noise {cfg.sim.odometry_noise:.0%}; camera "
        f"{cfg.sim.width}x{cfg.sim.height}\n\nAction budget: max({cfg.tree.budget_actions}, "
        f"{cfg.tree.budget_path_factor:g} x shortest path / 0.25 m, the episode's own budget).\n\n"
        + "Tiers:\n"
        + tier_definition()
    )
    md = save_evaluation(results, out, header)
    typer.echo(comparison_markdown(results))
    typer.echo(f"wrote {md} and {out / 'results.json'}")
