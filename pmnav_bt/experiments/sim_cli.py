"""``pmnav sim``: look at a simulated building, generate episodes, run the tree in the
simulator and evaluate it. It joins simulator, tree and metrics, so it lives in the
experiments layer; ``pmnav_bt.experiments.cli`` mounts it."""

from __future__ import annotations

import math
import sys
import time
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import NoReturn

import typer

from pmnav_bt import cli_values
from pmnav_bt.errors import PmNavError
from pmnav_bt.experiments import results_folder
from pmnav_bt.experiments.options import (
    building_names,
    class_ranges,
    job_count,
    ranges_text,
    run_config,
    table3_building_names,
    tier_names,
    variant_names,
)
from pmnav_bt.experiments.results_folder import OVERWRITE_OPT
from pmnav_bt.loading import check_output_dir, check_output_file, safe_filename
from pmnav_bt.registry import grounder_label
from pmnav_bt.sim.poses import PoseError, parse_pose  # noqa: F401 - PoseError: part of this CLI

app = typer.Typer(
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="The pybullet simulator: build a world from a building file and look at it.",
)


@app.callback()
def _group() -> None:
    """The pybullet simulator: build a world from a building file and look at it."""


CONFIG_OPT = typer.Option(None, "--config", help="A run config YAML (see docs/config.md).")
SET_OPT = typer.Option(None, "--set", help="Override a config value: section.key=value.")


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
    seed: int = typer.Option(0, "--seed", help="The episode seed the scene is drawn from."),
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Write a top-down plan and the first-person RGB, depth and segmentation views of the
    world a run with this config and seed drives in (`--set world.preset=realistic`)."""
    from pmnav_bt.sim.render import (
        annotate_labels,
        colorize_depth,
        colorize_segmentation,
        draw_top_down,
    )
    from pmnav_bt.sim.robot import SimBase
    from pmnav_bt.sim.textures import write_png
    from pmnav_bt.sim.world import SimWorld

    cli_values.seed(seed)
    cfg = run_config(config, overrides)
    start = parse_pose(pose) if pose is not None else None
    check_output_dir(out)
    with SimWorld(building, gui=gui, walls=cfg.sim.walls, scene=cfg.world, seed=seed) as world:
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
        if world.wall_source == "grid":
            from pmnav_bt.sim.wall_mounting import summary

            typer.echo(summary(world.moved_items))
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


@app.command()
def episodes(
    building: str = typer.Argument(..., help="A building or site file, or a built-in name."),
    tier: str = typer.Option(
        "easy", "--tier", help="easy, medium, hard, cross_level (a site of levels), a list, or all."
    ),
    n: int = typer.Option(20, "-n", min=1, help="Episodes per tier."),
    seed: int = typer.Option(0, "--seed"),
    out: Path | None = typer.Option(None, "--out", help="JSON file (default: standard output)."),
) -> None:
    """Generate seeded episodes of tiers as JSON (on standard output, or to --out).

    The tier definitions go to standard error.
    """
    from pmnav_bt.experiments.evaluation import episodes_for
    from pmnav_bt.sim.episodes import episodes_json, save_episodes, tier_definition

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    if out is not None:
        check_output_file(out, "--out", (".json",))
    eps, notes = episodes_for([building], tier_names(tier), n, seed)
    if not eps:
        raise PmNavError("; ".join(notes) or "no episodes")
    for note in notes:
        typer.echo(f"note: {note}", err=True)
    text = episodes_json(eps)
    typer.echo(tier_definition(), err=True)
    if out is None:
        sys.stdout.write(text)
        return
    save_episodes(eps, out)
    typer.echo(f"wrote {len(eps)} episodes to {out}", err=True)


@app.command()
def run(
    building: str = typer.Option("fig2_hospital", "--building", help="A building or built-in."),
    goal: str | None = typer.Option(
        None, "--goal", help="The goal room: ID, name or alias (not with --episodes)."
    ),
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
    view: bool = typer.Option(
        False, "--view", help="Serve the live web view of the run (see 'pmnav view')."
    ),
    view_port: int = typer.Option(8765, "--view-port", help="Port of --view (0: any free one)."),
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Run one PM-Nav episode and print its result; write the tree log and trajectory plot.
    In a site of several levels (--building hospital_2l), the goal may be on another
    level than the start ("L2/x,y,yaw_deg"; default: the first level's start): the robot
    rides the lift, and a trajectory plot is drawn per level.

    With --view, a browser page shows the run live; on a terminal it stays up after the
    run until Ctrl-C."""
    from pmnav_bt.experiments.evaluation import custom_episode, run_episode
    from pmnav_bt.tree_variants import TREE_VARIANTS

    cli_values.seed(seed)
    cli_values.index(index)
    cfg = run_config(config, overrides)
    check_output_dir(out)
    if episode_file is None and goal is not None:
        from pmnav_bt.experiments.site_run import run_site, site_of_levels

        if site_of_levels(building):  # a site: its levels joined by lifts
            run_site(building, goal, start, seed, cfg, out)
            return
    if episode_file is not None:
        from pmnav_bt.sim.episodes import episode_map, load_episodes
        from pmnav_bt.sim.site_episodes import SiteEpisode

        if goal is not None or start is not None:
            raise PmNavError("--episodes runs a stored episode: drop --goal and --start")
        eps = load_episodes(episode_file)
        if not 0 <= index < len(eps):
            raise PmNavError(f"--index {index}: {episode_file} has {len(eps)} episodes")
        ep = eps[index]
        if isinstance(ep, SiteEpisode):  # across levels: a world per level, a plot per level
            from pmnav_bt.experiments.site_run import show_site_run

            show_site_run(ep, cfg, out)
            return
        episode_map(ep)  # a missing, changed or other building, a start outside: now
    elif goal is None:
        raise PmNavError("give --goal ROOM (or --episodes FILE --index N)")
    else:
        ep = custom_episode(building, goal, start, seed)
    live = None
    if show_tree:
        from pmnav_bt.trees.live import LiveTree

        live = LiveTree()
    typer.echo(
        f"{TREE_VARIANTS.spec(cfg.tree.variant).label} [{grounder_label(cfg.grounder.backend)}] in "
        f"{ep.building}: {ep.id} ({ep.tier}), "
        f"start ({ep.start_x:.1f}, {ep.start_y:.1f}, {math.degrees(ep.start_yaw):.0f} deg), "
        f"corridor route {ep.route_length:.1f} m"
    )
    with _live_view(view, view_port, out) as (sink, hold):
        if live is not None:
            with live:
                r = run_episode(ep, cfg, out_dir=out, on_tick=live, also_log=sink)
        else:
            r = run_episode(ep, cfg, out_dir=out, also_log=sink)
        res = r.result
        typer.echo(
            f"{'SUCCESS' if res.success else 'FAILURE'}: SPL {res.spl:.3f}, {res.steps} actions, "
            f"{res.path_length:.1f} m driven (shortest {res.shortest_path_length:.1f} m), "
            f"{res.collisions} collisions, {res.people_contacts} people contacts, "
            f"stopped {res.distance_to_door:.2f} m from the door, "
            f"{res.wall_time:.1f} s wall"
        )
        if res.failure_reason:
            typer.echo(f"reason: {res.failure_reason}")
        typer.echo(f"tree log: {r.tree_log}\ntrajectory plot: {r.plot}")
        typer.echo(f"map updates: {r.map_updates} (review: pmnav map updates FILE)")
        hold()
    if not res.success:
        raise typer.Exit(1)


@contextmanager
def _live_view(on: bool, port: int, out: Path):
    """With ``on``: a web view server fed by the run's tree log lines. Yields the sink
    for them (None without ``on``) and ``hold()``: after the run, on a terminal, serve on
    until Ctrl-C (a run stopped by Ctrl-C, or not on a terminal, closes the view at once)."""
    if not on:
        yield None, lambda: None
        return
    from pmnav_bt.webview.cli import start_server
    from pmnav_bt.webview.feed import Feed, FeedWriter

    feed = Feed(f"pmnav sim run --out {out}", live=True)
    server = start_server(feed, "127.0.0.1", port, allow_remote=False)
    typer.echo(f"live view: {server.url}")
    writer = FeedWriter(feed)

    def hold() -> None:
        writer.close()
        if sys.stdin.isatty():
            typer.echo(f"the run is over; the view stays at {server.url}: Ctrl-C to stop")
            with suppress(KeyboardInterrupt):
                while True:
                    time.sleep(1.0)

    try:
        yield writer, hold
    finally:
        writer.close()
        server.close()


RAY_OPT = typer.Option(
    None,
    "--ray",
    help="Run episodes as Ray tasks: '--ray' alone starts a local Ray with --jobs CPUs; "
    "'--ray ADDRESS' joins a cluster (ray://head:10001, head:6379, auto). Needs the "
    "[ray] extra.",
)
WORLDS_OPT = typer.Option(
    "clean,realistic",
    "--worlds",
    help="Run every variant in each of these world presets, side by side (clean: the paper's "
    "worlds; realistic: signage of every kind, clutter, people, doors, light and camera; "
    "docs/worlds.md); keys of the world section set by --config/--set carry over.",
)
RESUME_OPT = typer.Option(
    False,
    "--resume",
    help="Keep the results.jsonl in --out and run only what it lacks (refused if it was "
    "made under another config).",
)


def reading_note(cfg) -> str:
    """The header's note of the width signs are read at, where the camera offers one."""
    from pmnav_bt.perception.read_range import reading_width

    w = reading_width(cfg)
    if w <= cfg.sim.width:
        return ""
    return f", signs read at {w}x{round(w * cfg.sim.height / cfg.sim.width)}"


def eval_header(building, tier, n, seed, cfg, configs) -> str:
    """The results.md header: what ran, each variant's grounder, the tier rules."""
    from pmnav_bt.eval.task import budget_rule
    from pmnav_bt.eval.tiers import tier_definition
    from pmnav_bt.experiments.variants import variant_title

    g = cfg.grounder
    grounders = "; ".join(
        f"{variant_title(name)}: grounder {grounder_label(c.grounder.backend)}"
        for name, c in configs.items()
    )
    return (
        f"# PM-Nav evaluation\n\nbuildings: {building}; tiers: {tier}; {n} per tier per "
        f"building; seed {seed}; {grounders} (miss {g.miss_rate:.0%}, false positives "
        f"{g.false_positive_rate:.0%}); odometry noise {cfg.sim.odometry_noise:.0%}; camera "
        f"{cfg.sim.width}x{cfg.sim.height}{reading_note(cfg)}\n\nTiers:\n"
        + tier_definition(budget_rule(cfg.tree.budget_actions, cfg.tree.budget_path_factor))
    )


@app.command("eval")
def eval_(
    building: str = typer.Option(
        "all",
        "--building",
        help="Comma-separated building files or built-in names, 'all' (the built-ins), or "
        "FAMILY:N (the first N generated buildings: gen_small:100, sign_sparse:3, hospital:10; "
        "functional:12 takes hospital, school and office in turn), or FAMILY_heldout:N (held-out "
        "members, for evaluation only: functional_heldout:12).",
    ),
    tier: str = typer.Option(
        "all", "--tier", help="easy, medium, hard, cross_level (sites of levels), a list, or all."
    ),
    n: int = typer.Option(20, "-n", min=1, help="Episodes per tier per building."),
    seed: int = typer.Option(0, "--seed"),
    variants: str = typer.Option(
        "pmnav,coarse_only,pmnav_oracle",
        "--variants",
        help="Comma-separated evaluation variants (pmnav, coarse_only, pmnav_oracle, mapless; "
        "VARIANT@WORLD runs one in a world preset).",
    ),
    worlds: str = WORLDS_OPT,
    jobs: int | None = typer.Option(
        None, "--jobs", help="Episodes run in parallel [default: 2, at most the CPUs]."
    ),
    out: Path = typer.Option(Path("out/eval"), "--out", help="Folder for results.json/.md."),
    resume: bool = RESUME_OPT,
    overwrite: bool = OVERWRITE_OPT,
    ray: str | None = RAY_OPT,
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Run many episodes and print SR/SPL per tier for each variant (paper Table 1).

    Results stream to OUT/results.jsonl as each episode ends; Ctrl-C keeps them and
    writes a partial table; --resume goes on from them. Exits 1 when episodes could not
    be run (errors are counted apart from failures).
    """
    from pmnav_bt.experiments.evaluation import (
        comparison_markdown,
        episodes_for,
        error_counts,
        save_evaluation,
        variant_configs,
    )
    from pmnav_bt.experiments.stored_run import StoredRun, run_stored_evaluation

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    jobs = job_count(jobs)
    cfg = run_config(config, overrides)
    check_output_dir(out)
    work = results_folder.claim(out, resume, overwrite)
    names = variant_names(variants, worlds)
    configs = variant_configs(cfg, names)
    eps, notes = episodes_for(building_names(building), tier_names(tier), n, seed)
    for note in notes:
        typer.echo(f"note: {note}", err=True)
    if not eps:
        raise PmNavError("no episodes to run")
    echo = lambda text: typer.echo(text, err=True)  # noqa: E731
    run = run_stored_evaluation(eps, configs, StoredRun(work, jobs, ray, resume, echo))
    header = eval_header(building, tier, n, seed, cfg, configs)
    results = {k: v for k, v in run.results.items() if v}
    if run.stopped_by:

        def keep_partial() -> str:
            done = sum(map(len, results.values()))
            note = f"(partial: stopped by {run.stopped_by}, {done} of {run.total} runs)"
            title = "# PM-Nav evaluation"
            save_evaluation(results, work, header.replace(title, f"{title} {note}", 1))
            return comparison_markdown(results)

        partial = keep_partial if results else None
        _stopped(run, work, out, run.resumed + run.new, "episodes", partial)
    save_evaluation(results, work, header)
    results_folder.publish(work, out)
    typer.echo(comparison_markdown(results))
    typer.echo(f"wrote {out / 'results.md'} and {out / 'results.json'}")
    errors = error_counts(results)
    if errors:
        first = next(r.error for rs in results.values() for r in rs if r.error)
        counts = ", ".join(f"{name} {c} of {len(results[name])}" for name, c in errors.items())
        typer.echo(
            f"error: episodes could not be run ({counts}); first: {first}; "
            f"see {out / 'results.json'}",
            err=True,
        )
        raise typer.Exit(1)


def _stopped(run, work: Path, out: Path, done: int, unit: str, keep_partial) -> NoReturn:
    """End a run stopped by a signal: save and show the partial table (``keep_partial``
    writes it into ``work`` and returns its text; None when nothing finished), say where
    the finished rows are and how to go on, and exit with the signal's status (130, 143).
    An ``--overwrite`` run's ``work`` is its staging folder: ``out`` keeps the earlier
    results."""
    if keep_partial is not None:
        typer.echo(keep_partial(), err=True)
    typer.echo(
        f"pmnav: stopped by {run.stopped_by} after {done} of {run.total} {unit}; finished "
        f"ones are in {work / 'results.jsonl'} (go on with --resume)"
        + results_folder.stopped_note(work, out),
        err=True,
    )
    raise typer.Exit(run.exit_code)


@app.command("table3")
def table3(
    building: str = typer.Option(
        "all,sign_sparse",
        "--building",
        help="Comma-separated buildings; 'all' = the six built-ins, 'sign_sparse' = the "
        "generated sign-sparse family (--family-size members).",
    ),
    n: int = typer.Option(5, "-n", min=1, help="Start poses per landmark class per building."),
    family_size: int = typer.Option(3, "--family-size", min=1, help="Sign-sparse buildings."),
    seed: int = typer.Option(0, "--seed"),
    jobs: int = typer.Option(1, "--jobs", min=1, help="Runs in parallel."),
    out: Path = typer.Option(Path("out/table3"), "--out", help="Folder for results.json/.md."),
    resume: bool = RESUME_OPT,
    overwrite: bool = OVERWRITE_OPT,
    ray: str | None = RAY_OPT,
    class_range: str = typer.Option(
        "stack",
        "--class-range",
        help="What 'readable' means for the start classes: 'stack' = within the "
        "configured grounder's reliable read range per plate kind (the oracle: the map's "
        "9.5 m); 'map' = within the map's 9.5 m whatever reads the signs (earlier rounds).",
    ),
    config: Path | None = CONFIG_OPT,
    overrides: list[str] | None = SET_OPT,
) -> None:
    """Localization alone from start poses classed by readable landmarks (paper Table 3)."""
    from pmnav_bt.experiments.localization_study import (
        SUCCESS_POS_M,
        SUCCESS_YAW_DEG,
        classified_starts,
        save,
        table,
    )
    from pmnav_bt.experiments.stored_run import StoredRun, run_stored_study

    check_output_dir(out)
    work = results_folder.claim(out, resume, overwrite)
    cfg = run_config(config, overrides)
    ranges = class_ranges(class_range, cfg)
    names = table3_building_names(building, family_size)
    starts = [s for b in names for s in classified_starts(b, n, seed, ranges)]
    if not starts:
        raise PmNavError("no start poses to run")
    echo = lambda text: typer.echo(text, err=True)  # noqa: E731
    run = run_stored_study(starts, cfg, StoredRun(work, jobs, ray, resume, echo))
    results = run.results
    header = (
        f"# Localization by landmark density (paper Table 3)\n\nbuildings: {', '.join(names)}; "
        f"up to {n} starts per class per building; seed {seed}; grounder "
        f"{grounder_label(cfg.grounder.backend)} "
        f"(miss {cfg.grounder.miss_rate:.0%}); odometry noise {cfg.sim.odometry_noise:.0%}.\n"
        f"Class: signs the priori-map says are readable from the start (line of sight, "
        f"{ranges_text(ranges)}): redundant > 2, minimal = 2, scarce 0-1. Success: the "
        f"localization subtree succeeds within {SUCCESS_POS_M:g} m and {SUCCESS_YAW_DEG:g} deg "
        "of the truth. SDF = S * 2 / max(2, d), d = panoramas taken."
    )
    if run.stopped_by:

        def keep_partial() -> str:
            save(results, work, header + f"\n\nPARTIAL: stopped by {run.stopped_by}.")
            return table(results)

        _stopped(run, work, out, len(results), "runs", keep_partial if results else None)
    save(results, work, header)
    results_folder.publish(work, out)
    typer.echo(header)
    typer.echo(table(results))
    typer.echo(f"wrote {out / 'results.md'} and {out / 'results.json'}")


from pmnav_bt.experiments.belief_show import belief as _belief  # noqa: E402 - its module's command

app.command("belief")(_belief)

from pmnav_bt.experiments.world_sheet import sheet as _sheet  # noqa: E402 - its module's command

app.command("sheet")(_sheet)
