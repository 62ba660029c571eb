"""``pmnav plan``: plan a route (the default command) and evaluate VLM planning (Table 2).

``pmnav plan FILE --from S --to G`` stays as it was: a first argument that is not a
subcommand runs ``pmnav plan route``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from typer.core import TyperGroup

from pmnav_bt.errors import PmNavError
from pmnav_bt.experiments import results_folder

FILE_HELP = "A building file (YAML) or the name of a built-in building (see 'pmnav buildings')."


class _RouteByDefault(TyperGroup):
    """A group whose default command is ``route``."""

    def parse_args(self, ctx, args):
        if args and args[0] not in self.commands and args[0] not in ("--help", "-h"):
            args = ["route", *args]
        return super().parse_args(ctx, args)


app = typer.Typer(
    cls=_RouteByDefault,
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="Plan from a start to a goal room ('pmnav plan FILE --from S --to G'), or evaluate "
    "VLM planning ('pmnav plan eval').",
)


@app.command()
def route(
    file: str = typer.Argument(..., help=FILE_HELP),
    start: str = typer.Option(
        ...,
        "--from",
        help="Start: a segment (seg13), a waypoint or room ID, or a pose 'x,y[,yaw_deg]'.",
    ),
    goal: str = typer.Option(
        ...,
        "--to",
        help="Goal room: ID, name or alias; in a site, on any level, or qualified by its "
        "level: 'L2/room 208' or 'room 208 on L2'.",
    ),
    start_level: str | None = typer.Option(
        None, "--start-level", help="A site's level the start is on (default: its first)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the plan as JSON."),
    image: Path | None = typer.Option(None, "--image", help="Draw the plan on the annotated map."),
    max_gap: float | None = typer.Option(
        None, help="Most metres between consecutive plan steps (default: the planner's, 8)."
    ),
    planner: str = typer.Option("graph", "--planner", help="graph or vlm (see docs/vlm.md)."),
    config: Path | None = typer.Option(None, "--config", help="A run config YAML."),
    overrides: list[str] | None = typer.Option(
        None, "--set", help="Override a config value: section.key=value (vlm.base_url=...)."
    ),
) -> None:
    """Plan from a start to a goal room: ordered {landmark: action} steps."""
    from pmnav_bt.cli import IMAGE_SUFFIXES, _folder, _priori_map
    from pmnav_bt.cli_values import finite
    from pmnav_bt.config import load_config
    from pmnav_bt.loading import check_output_file
    from pmnav_bt.planning.graph_planner import GraphPlanner

    if max_gap is not None:
        finite(max_gap, "--max-gap", 0.1, 1000.0)
    if image is not None:
        check_output_file(image, "--image", IMAGE_SUFFIXES)
    from pmnav_bt.map.site_cli import names_site

    if start_level is not None or names_site(file):
        opts = (as_json, image, max_gap, planner, config, overrides)
        _site_route(file, start_level, start, goal, *opts)
        return
    pm = _priori_map(file)
    if planner == "graph":
        p = (GraphPlanner() if max_gap is None else GraphPlanner(max_gap=max_gap)).plan(
            pm, start, goal
        )
    else:
        from pmnav_bt.backends import BackendDeps
        from pmnav_bt.registry import PLANNERS

        gap = [] if max_gap is None else [f"planner.max_gap={max_gap}"]
        cfg = load_config(config, [*(overrides or []), *gap])
        p = PLANNERS.build(planner, BackendDeps(config=cfg, pm=pm)).plan(pm, start, goal)
    typer.echo(p.to_json() if as_json else p.text())
    if image is not None:
        from pmnav_bt.render.annotate import render_annotated_map

        render_annotated_map(pm, path=image, path_xy=list(p.path), base_dir=_folder(file))
        typer.echo(f"wrote {image}", err=True)


def _site_route(
    file: str,
    start_level: str | None,
    start: str,
    goal: str,
    as_json: bool,
    image: Path | None,
    max_gap: float | None,
    planner: str,
    config: Path | None,
    overrides: list[str] | None,
) -> None:
    """``pmnav plan SITE``: a plan across levels, legs and rides; an image per level."""
    from pmnav_bt.config import load_config
    from pmnav_bt.map.site import open_site
    from pmnav_bt.map.site_cli import render_site_images
    from pmnav_bt.map.site_map import parse_site
    from pmnav_bt.planning.site_planners import build_site_planner

    sm = parse_site(open_site(file))
    level = start_level or sm.site.levels[0].name
    sets = [*(overrides or []), *([] if max_gap is None else [f"planner.max_gap={max_gap}"])]
    cfg = load_config(config, sets)
    p = build_site_planner(planner, cfg, sm).plan(sm, level, start, goal)
    typer.echo(p.to_json() if as_json else p.text())
    if image is not None:
        paths = {leg.level: list(leg.plan.path) for leg in p.legs}
        one = None if sm.single else (level if len(paths) == 1 else None)
        for out in render_site_images(sm, image, one, paths):
            typer.echo(f"wrote {out}", err=True)


@app.command("eval")
def eval_(
    endpoint: str = typer.Option(
        None, "--endpoint", help="OpenAI-compatible base URL, e.g. http://127.0.0.1:8000/v1."
    ),
    model: str = typer.Option(None, "--model", help="The model name the server serves."),
    inputs: str = typer.Option("o-em,h-em,h-pm", "--inputs", help="Comma-separated inputs."),
    building: str = typer.Option("all", "--building", help="Comma-separated buildings, or all."),
    tier: str = typer.Option("all", "--tier", help="easy, medium, hard or all."),
    n: int = typer.Option(8, "-n", min=1, help="Tasks per tier per building."),
    seed: int = typer.Option(0, "--seed"),
    tries: int = typer.Option(1, "--tries", min=1, help="Answers per task (re-prompts + 1)."),
    margin: float = typer.Option(0.1, "--margin", min=0.0, help="Allowed detour (0.1 = 10%)."),
    out: Path = typer.Option(Path("out/plan_eval"), "--out", help="Results and transcripts."),
    overwrite: bool = results_folder.OVERWRITE_OPT,
    replay_dir: Path | None = typer.Option(
        None, "--replay", help="Re-score the transcripts in this folder (no server)."
    ),
    config: Path | None = typer.Option(None, "--config", help="A run config YAML (vlm: ...)."),
    overrides: list[str] | None = typer.Option(None, "--set", help="section.key=value"),
) -> None:
    """Planning SR per input and tier (paper Table 2), against an OpenAI-compatible server."""
    from pmnav_bt import cli_values
    from pmnav_bt.experiments.options import building_names, name_list, tier_names
    from pmnav_bt.experiments.plan_eval import (
        correct_rule,
        plan_tasks,
        replay,
        run_plan_eval,
        save_results,
        table_markdown,
    )
    from pmnav_bt.loading import check_output_dir
    from pmnav_bt.sim.episodes import tier_definition

    cli_values.finite(margin, "--margin", 0.0, 10.0)
    if replay_dir is not None:
        check_output_dir(replay_dir, "--replay")
        results = replay(replay_dir, margin)
        header = (
            f"# VLM planning (paper Table 2), re-scored from the transcripts in {replay_dir}\n\n"
            f"Correct: {correct_rule(margin)}"
        )
        md = save_results(results, replay_dir, header, name="replay")
        typer.echo(table_markdown(results))
        typer.echo(f"wrote {md}")
        return
    from pmnav_bt.config import load_config
    from pmnav_bt.vlm.client import VlmClient

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    names = name_list(inputs, "--inputs")
    check_output_dir(out)
    work = results_folder.claim(out, False, overwrite)
    sets = list(overrides or [])
    if endpoint:
        sets.append(f"vlm.base_url={endpoint}")
    if model:
        sets.append(f"vlm.model={model}")
    cfg = load_config(config, sets)
    client = VlmClient.from_config(cfg.vlm)
    tasks, notes = plan_tasks(building_names(building), tier_names(tier), n, seed)
    for note in notes:
        typer.echo(f"note: {note}", err=True)
    if not tasks:
        raise PmNavError("no plan tasks")
    step = max(1, (len(tasks) * len(names)) // 10)

    def report(done: int, total: int) -> None:
        if done % step == 0 or done == total:
            typer.echo(f"{done}/{total} conversations", err=True)

    results = run_plan_eval(
        client, tasks, names, work, tries, margin, cfg.vlm.image_px, progress=report
    )
    totals = client.totals()
    header = (
        f"# VLM planning (paper Table 2)\n\nserver {cfg.vlm.base_url}, model {cfg.vlm.model}; "
        f"buildings: {building}; tiers: {tier}; {n} tasks per tier per building (seed {seed}); "
        f"{tries} answer(s) per task; {totals['calls']} calls, {totals['failed_calls']} failed, "
        f"{totals['prompt_tokens']} prompt + {totals['completion_tokens']} completion tokens, "
        f"{totals['latency_s']:.1f} s.\n\nCorrect: {correct_rule(margin)}\n\nTasks: the episodes "
        f"of 'pmnav sim eval'.\n{tier_definition()}"
    )
    save_results(results, work, header)
    results_folder.publish(work, out)
    typer.echo(table_markdown(results))
    typer.echo(f"wrote {out / 'results.md'}, {out / 'results.json'} and {len(results)} transcripts")
    if sys.stderr.isatty():
        typer.echo(f"re-score with: pmnav plan eval --replay {out}", err=True)
