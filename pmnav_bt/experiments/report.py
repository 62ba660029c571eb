"""``pmnav report``: run (or resume) the evaluation and the Table 3 study into one folder,
then write report.md: Tables 1, 3 and 4 beside the paper's, plots, a few trajectories,
the exact configuration and the commit. ``--from DIR`` only re-renders DIR.

Folder: meta.json (what was asked, each variant's config), config.yaml, eval/ and table3/
(results.jsonl, results.md, results.json), plots/*.png, trajectories/<variant>/*.png,
report.md.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import typer
import yaml

from pmnav_bt.config import Config
from pmnav_bt.errors import PmNavError
from pmnav_bt.experiments import results_folder
from pmnav_bt.loading import atomic_write_text, check_output_dir

META = "meta.json"
# What makes a folder hold a report: its evaluation's store first (what --resume goes on from).
REPORT_FILES = ("eval/results.jsonl", "table3/results.jsonl", "report.md")


def git_commit() -> str:
    """The project's commit (``git describe --always --dirty``), or "unknown"."""
    root = Path(__file__).resolve().parents[2]
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    return out.stdout.strip() or "unknown"


def load_eval_rows(path: Path, configs: dict[str, Config]) -> dict[str, list]:
    """results.jsonl -> variant -> EpisodeResults, for the variants of ``configs`` in
    their order, made under exactly those configs (first row of each key; a torn tail
    ignored)."""
    from pmnav_bt.experiments.runstore import read_rows
    from pmnav_bt.experiments.stored_run import result_of
    from pmnav_bt.experiments.variants import config_hash

    rows, _ = read_rows(path)
    hashes = {n: config_hash(c) for n, c in configs.items()}
    seen: set = set()
    out: dict[str, list] = {n: [] for n in configs}
    for row in rows:
        if row.get("key") in seen or hashes.get(row.get("variant")) != row.get("config_sha"):
            continue
        seen.add(row.get("key"))
        out[row["variant"]].append(result_of(row))
    return {n: rs for n, rs in out.items() if rs}


def load_study_rows(path: Path) -> list:
    from pmnav_bt.experiments.localization_study import result_of_row
    from pmnav_bt.experiments.runstore import read_rows

    rows, _ = read_rows(path)
    seen: set = set()
    out = []
    for row in rows:
        if row.get("key") not in seen:
            seen.add(row.get("key"))
            out.append(result_of_row(row))
    return out


def render_report(folder: Path) -> Path:
    """Write ``folder``/report.md (and its plots) from the results on disk."""
    from pmnav_bt.experiments import report_tables as T
    from pmnav_bt.experiments.localization_study import table as table3
    from pmnav_bt.experiments.report_plots import plot_failures, plot_sr_spl
    from pmnav_bt.experiments.variants import variant_title

    meta_path = folder / META
    if not meta_path.is_file():
        raise PmNavError(f"--from {folder}: no {META} there (not a pmnav report folder)")
    meta = json.loads(meta_path.read_text(encoding="utf-8"))
    configs = {n: Config.model_validate(c) for n, c in meta["variant_configs"].items()}
    results = load_eval_rows(folder / "eval" / "results.jsonl", configs)
    study = load_study_rows(folder / "table3" / "results.jsonl")
    ev, t3 = meta["eval"], meta.get("table3")
    expected = meta.get("expected_runs")
    done = sum(map(len, results.values()))
    lines = [
        "# PM-Nav BT: evaluation report",
        "",
        f"Commit `{meta['commit']}`; made {meta['made']}; command: `{meta['command']}`.",
        "Re-render with `pmnav report --from " + str(folder) + "`.",
        "",
    ]
    if expected and done < expected:
        lines += [f"**PARTIAL**: {done} of {expected} evaluation runs finished.", ""]
    lines += [
        "## What ran",
        "",
        f"Buildings: {ev['building']}; tiers: {ev['tier']}; {ev['n']} episodes per tier per "
        f"building (fewer where a building cannot pose a tier); seed {ev['seed']}. Simulator: "
        "pybullet, discrete actions, the tier, budget and success rules of "
        "`pmnav sim eval` (below). SR and SPL in %.",
        "",
        T.variants_table(results, configs),
        "",
        "## Table 1: navigation per tier, beside the paper",
        "",
        "The paper's rows are its simulation numbers (Gazebo, its own six buildings, a VLM "
        "and GroundingDINO/SAM); ours are this simulator's buildings: compare shapes, not "
        "digits. The map-less baseline stands where the paper has SG-Nav and InstructNav "
        "(zero-shot navigators without a prior map).",
        "",
        T.table1(results) if results else "(no results)",
        "",
        "![SR and SPL per tier](plots/sr_spl.png)",
        "",
    ]
    cross = T.cross_level_table(results)
    if cross is not None:
        lines += [
            "## Across levels: start and goal on different levels, by lift",
            "",
            "Tier cross_level (sites of several levels): success is stopping within 1 m of "
            "the door on the goal level. Rides: lift rides on the episodes' routes; lift "
            "full met: calls the lift answered with a full cabin (`world.lift_full_p`).",
            "",
            cross,
            "",
        ]
    lines += [
        "## Table 3: localization by landmark density, beside the paper",
        "",
    ]
    if study:
        g = configs.get("pmnav", next(iter(configs.values()), None))
        lines += [
            f"Buildings: {t3['building']} ({t3['n']} starts per class per building); "
            f"grounder {t3.get('grounder', g.grounder.backend if g else '?')}. Class: signs "
            "readable from the start by the priori-map's visibility model "
            f"({t3.get('class_range', '<= 9.5 m')}): redundant > 2, "
            "minimal = 2, scarce 0-1. SDF = S * 2 / max(2, panoramas).",
            "",
            table3(study),
        ]
    else:
        lines.append("(not run: `--no-table3`, or no results yet)")
    lines += [
        "",
        "## Table 4: action refinement, beside the paper",
        "",
        "Coarse-only (the panorama's 30-degree heading, no refinement) against fine "
        "refinement (geometric; PixelNav when its variant ran), with the perception stack "
        "of each variant's grounder (above), and the simulator-label oracle as a bound.",
        "",
        T.table4(results) if results else "(no results)",
        "",
        "## Failures",
        "",
        T.failures_table(results),
        "",
        "![Failure codes per variant](plots/failures.png)",
        "",
        "Per building (all tiers):",
        "",
        T.per_building_table(results),
        "",
        "## Contacts",
        "",
        "The robot's collisions with anything and its contacts with people, per variant "
        "(targets: people 0, collisions <= 1 per 100 episodes).",
        "",
        T.contacts_table(results),
        "",
    ]
    if results:
        plot_sr_spl(results, folder / "plots" / "sr_spl.png")
        plot_failures(results, folder / "plots" / "failures.png")
    trajectories = sorted((folder / "trajectories").glob("*/*.png"))
    if trajectories:
        lines += ["## Trajectories", ""]
        for p in trajectories:
            rel = p.relative_to(folder)
            lines.append(f"- {variant_title(p.parent.name)}: [{p.stem}]({rel})")
        lines.append("")
    lines += [
        "## Configuration",
        "",
        "Each variant's config is the base below with its overrides; the config hash is "
        "the one its results.jsonl rows carry.",
        "",
        "```yaml",
        (folder / "config.yaml").read_text(encoding="utf-8").rstrip(),
        "```",
        "",
        "## Tier rules",
        "",
        "```",
        meta.get("tiers", ""),
        "```",
        "",
    ]
    return atomic_write_text(folder / "report.md", "\n".join(lines))


def _write_meta(out: Path, base: Config, configs: dict, ev: dict, t3: dict | None, total: int):
    from pmnav_bt.eval.task import budget_rule
    from pmnav_bt.eval.tiers import tier_definition
    from pmnav_bt.experiments.variants import config_hash, find_variant

    meta = {
        "commit": git_commit(),
        "made": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "command": " ".join(["pmnav", *sys.argv[1:]]),
        "eval": ev,
        "table3": t3,
        "expected_runs": total,
        "variant_configs": {n: c.model_dump(mode="json") for n, c in configs.items()},
        "tiers": tier_definition(
            budget_rule(base.tree.budget_actions, base.tree.budget_path_factor)
        ),
    }
    atomic_write_text(out / META, json.dumps(meta, indent=1))
    doc = {
        "base": base.model_dump(mode="json"),
        "variants": {
            n: {
                "overrides": dict(v.overrides) if (v := find_variant(n)) else {},
                "oracle": bool(v.oracle) if v else False,
                "config_hash": config_hash(c),
            }
            for n, c in configs.items()
        },
    }
    atomic_write_text(out / "config.yaml", yaml.safe_dump(doc, sort_keys=False))


def pick_trajectories(results: dict, k: int) -> list[tuple[str, str]]:
    """Up to ``k`` (variant, episode id) to plot: the first Table-1 variant's success on
    the longest route of its hardest tier, its first failure, then that success's episode
    under the other Table-1 variants."""
    from pmnav_bt.eval.tiers import TIER_NAMES
    from pmnav_bt.experiments.variants import find_variant

    t1 = [n for n in results if (v := find_variant(n)) and "1" in v.tables]
    if not t1 or k <= 0:
        return []
    main = results[t1[0]]
    rank = {t: i for i, t in enumerate(TIER_NAMES)}
    by_hard = sorted(main, key=lambda r: (-rank.get(r.tier, -1), -(r.route_length or 0)))
    picks = []
    ok = next((r for r in by_hard if r.success), None)
    bad = next((r for r in by_hard if not r.success and r.error is None), None)
    if ok:
        picks.append((t1[0], ok.episode_id))
    if bad:
        picks.append((t1[0], bad.episode_id))
    if ok:
        picks += [(n, ok.episode_id) for n in t1[1:]]
    return picks[:k]


def run_trajectories(out: Path, episodes: list, configs: dict, picks) -> None:
    from pmnav_bt.experiments.evaluation import run_episode
    from pmnav_bt.experiments.site_run import run_site_episode
    from pmnav_bt.sim.site_episodes import SiteEpisode

    by_id = {e.id: e for e in episodes}
    for name, eid in picks:
        folder = out / "trajectories" / name
        if list(folder.glob(f"{eid}*.png")):
            continue
        ep = by_id[eid]
        if isinstance(ep, SiteEpisode):  # a plot per level
            run_site_episode(ep, configs[name], out_dir=folder)
        else:
            run_episode(ep, configs[name], out_dir=folder)
        for log in folder.glob("*.tree.jsonl"):
            log.unlink()  # the plot is what the report links; logs stay out of it


def report(
    out: Path = typer.Option(Path("out/report"), "--out", help="The report folder."),
    from_dir: Path | None = typer.Option(
        None, "--from", help="Only re-render the report of this folder from its results."
    ),
    building: str = typer.Option("all", "--building", help="As for pmnav sim eval."),
    tier: str = typer.Option("all", "--tier", help="easy, medium, hard, a list, or all."),
    n: int = typer.Option(20, "-n", min=1, help="Episodes per tier per building."),
    seed: int = typer.Option(0, "--seed"),
    variants: str = typer.Option(
        "", "--variants", help="Comma-separated variants [default: every registered one]."
    ),
    worlds: str = typer.Option(
        "clean,realistic",
        "--worlds",
        help="Run every variant in each of these world presets, side by side "
        "(docs/worlds.md).",
    ),
    table3_building: str = typer.Option(
        "all,sign_sparse", "--table3-building", help="Buildings of the Table 3 study."
    ),
    table3_n: int = typer.Option(5, "--table3-n", min=1, help="Starts per class per building."),
    family_size: int = typer.Option(3, "--family-size", min=1, help="Sign-sparse buildings."),
    no_table3: bool = typer.Option(False, "--no-table3", help="Leave the Table 3 study out."),
    trajectories: int = typer.Option(3, "--trajectories", min=0, help="Trajectory plots."),
    jobs: int | None = typer.Option(None, "--jobs", help="Runs in parallel [default: 2]."),
    resume: bool = typer.Option(False, "--resume", help="Go on from the results already in --out."),
    overwrite: bool = results_folder.OVERWRITE_OPT,
    ray: str | None = typer.Option(
        None, "--ray", help="Ray: alone, a local runtime; or a cluster address."
    ),
    config: Path | None = typer.Option(None, "--config", help="A run config YAML."),
    overrides: list[str] | None = typer.Option(None, "--set", help="section.key=value."),
) -> None:
    """Run (or resume) the evaluation and the Table 3 study, then write report.md with
    Tables 1, 3 and 4 beside the paper's, plots, trajectories, config and commit."""
    from pmnav_bt import cli_values
    from pmnav_bt.experiments import options
    from pmnav_bt.experiments.evaluation import episodes_for
    from pmnav_bt.experiments.localization_study import classified_starts
    from pmnav_bt.experiments.stored_run import StoredRun, run_stored_evaluation, run_stored_study
    from pmnav_bt.experiments.variants import VARIANTS, variant_configs

    if from_dir is not None:
        md = render_report(from_dir)
        typer.echo(f"wrote {md}")
        return
    cli_values.count(n, "-n")
    cli_values.seed(seed)
    jobs = options.job_count(jobs)
    base = options.run_config(config, overrides)
    check_output_dir(out)
    work = results_folder.claim(out, resume, overwrite, REPORT_FILES)
    names = options.variant_names(variants or ",".join(VARIANTS), worlds)
    configs = variant_configs(base, names)
    buildings, tiers = options.building_names(building), options.tier_names(tier)
    t3_names = [] if no_table3 else options.table3_building_names(
        table3_building, family_size, "--table3-building"
    )
    eps, notes = episodes_for(buildings, tiers, n, seed)  # every option read first: now work
    for note in notes:
        typer.echo(f"note: {note}", err=True)
    if not eps:
        raise PmNavError("no episodes to run")
    starts: list = []
    t3 = None
    if not no_table3:
        ranges = options.class_ranges("stack", base)
        starts = [s for b in t3_names for s in classified_starts(b, table3_n, seed, ranges)]
        t3 = {
            "building": ", ".join(t3_names),
            "n": table3_n,
            "grounder": base.grounder.backend,
            "class_range": options.ranges_text(ranges),
        }
    ev = {"building": building, "tier": tier, "n": n, "seed": seed}
    work.mkdir(parents=True, exist_ok=True)
    total = len(eps) * len(configs)
    _write_meta(work, base, configs, ev, t3, total)
    echo = lambda text: typer.echo(text, err=True)  # noqa: E731
    echo(f"evaluation: {total} runs ({len(eps)} episodes x {len(configs)} variants)")
    run = run_stored_evaluation(eps, configs, StoredRun(work / "eval", jobs, ray, resume, echo))
    stopped = run.stopped_by
    if not stopped and starts:
        echo(f"Table 3 study: {len(starts)} localization runs")
        study = run_stored_study(starts, base, StoredRun(work / "table3", jobs, ray, resume, echo))
        stopped = study.stopped_by
    if not stopped and trajectories:
        from pmnav_bt.interrupts import Interrupted, stop_signals

        with stop_signals():
            try:
                picks = pick_trajectories(run.results, trajectories)
                run_trajectories(work, eps, configs, picks)
            except Interrupted as stop:
                stopped = stop.signame
    md = render_report(work)
    if not stopped:
        results_folder.publish(work, out)
        md = out / md.name
    typer.echo(f"wrote {md}")
    if stopped:
        typer.echo(
            f"pmnav: stopped by {stopped}; {md} is partial; go on with the same "
            "command and --resume" + results_folder.stopped_note(work, out),
            err=True,
        )
        raise typer.Exit(130 if stopped == "SIGINT" else 143)
