"""Run PM-Nav episodes in the simulator and score them (SR, SPL as in the paper's Table 1).

This module joins the simulator and the tree, so it imports both lazily, inside the
functions: importing ``pmnav_bt.experiments.evaluation`` loads neither pybullet nor py_trees.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from pmnav_bt.config import Config
from pmnav_bt.eval.metrics import EpisodeResult, aggregate_by_tier, contact_totals
from pmnav_bt.loading import atomic_write_text, safe_filename
from pmnav_bt.registry import grounder_label
from pmnav_bt.tree_variants import TREE_VARIANTS

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.sim.episodes import Episode


@dataclass
class EpisodeRun:
    """An episode's result and the files written for it."""

    result: EpisodeResult
    plot: Path | None = None
    tree_log: Path | None = None
    map_updates: Path | None = None  # what the run saw that disagrees with the map


def custom_episode(building: str, goal: str, start: str | None = None, seed: int = 0) -> Episode:
    """An episode for ``pmnav sim run``: a goal by name, from a start pose or the building's
    start waypoint (facing along its corridor)."""
    from pmnav_bt.eval.task import action_budget
    from pmnav_bt.eval.tiers import classify
    from pmnav_bt.map.catalogue import building_sha256, open_building, resolve_building_path
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.planning.resolve import resolve_room, resolve_start
    from pmnav_bt.seams import Pose2D
    from pmnav_bt.sim.episodes import Episode, path_facts

    path = resolve_building_path(building).resolve()
    b = open_building(path)
    pm = parse_building(b)
    room = resolve_room(pm, goal)
    if start is None:
        w = next((w for w in b.waypoints if w.kind.value == "start"), b.waypoints[0])
        seg = pm.segments_at(w.id)[0]
        yaw = seg.heading if seg.a == w.id else seg.heading + math.pi
        pose = Pose2D(w.pos[0], w.pos[1], yaw)
        # Start a little into the corridor, not against the end wall.
        pose = Pose2D(pose.x + 0.5 * math.cos(yaw), pose.y + 0.5 * math.sin(yaw), yaw)
    else:
        sp = resolve_start(pm, start)
        a, c = pm.node_xy(sp.segment.a), pm.node_xy(sp.segment.b)
        xy = a + sp.t * (c - a)
        yaw = sp.heading if sp.heading is not None else sp.segment.heading
        pose = Pose2D(float(xy[0]), float(xy[1]), yaw)
    facts = path_facts(pm, pose, room)
    return Episode(
        id=f"{b.name}-{room}",
        building=b.name,
        tier=classify(facts) or "custom",
        start_x=pose.x,
        start_y=pose.y,
        start_yaw=pose.yaw,
        goal=room,
        route_length=facts.length,
        seed=seed,
        goal_visible=facts.goal_visible,
        turns=facts.turns,
        forks=facts.forks,
        route=tuple(facts.route),
        step_budget=action_budget(facts.length),
        building_path=str(path),
        building_sha256=building_sha256(path),
    )


def run_episode(
    episode: Episode,
    config: Config,
    out_dir: Path | None = None,
    on_tick: Callable | None = None,
    plot: bool = True,
    setup_world: Callable | None = None,
    also_log: TextIO | None = None,
) -> EpisodeRun:
    """Run one episode in a fresh world; write its tree log and trajectory plot to ``out_dir``.

    ``setup_world(world)`` may change the world first (add an obstacle, for example).
    ``also_log``: a second sink for the tree log's lines (the live web view, ``--view``).
    """
    from pmnav_bt.map.updates import SUFFIX as UPDATES_SUFFIX
    from pmnav_bt.map.updates import UpdatesFile
    from pmnav_bt.pose.evidence.floor_model import building_grid
    from pmnav_bt.sim.episodes import (
        episode_map,
        goal_door_in_world,
        goal_geodesic,
        score_episode,
    )
    from pmnav_bt.sim.odometry import simulated_robot
    from pmnav_bt.sim.robot import COLLISION_HEIGHT
    from pmnav_bt.sim.scene.blocking import block_segment
    from pmnav_bt.sim.scene.stale_map import stale_world
    from pmnav_bt.sim.world import SimWorld
    from pmnav_bt.trees.map_watch import watch_map
    from pmnav_bt.trees.runner import action_budget, make_context, run_tree
    from pmnav_bt.trees.view_record import ViewRecorder

    file, pm = episode_map(episode)
    b = pm.building
    folder = file.parent
    sim = config.sim
    t0 = time.perf_counter()
    stale = stale_world(pm, config.world, episode.seed, episode.route, episode.goal)
    with SimWorld(
        stale.building, walls=sim.walls, base_dir=folder, scene=config.world, seed=episode.seed
    ) as world:
        for ref in (*episode.blocked, *stale.closed):  # closed ways: the building as built
            block_segment(world, pm, ref)
        # SPL's shortest path: in the building as built (landmarks, not added obstacles).
        footprints = world.obstacle_footprints(COLLISION_HEIGHT)
        door = goal_door_in_world(world, pm, episode.goal)  # moved onto a grid wall, if so
        geodesic = goal_geodesic(
            pm, episode.goal, footprints, floor=world.floor_space(), door=door
        )
        if setup_world is not None:
            setup_world(world)
        inner, base = simulated_robot(world, sim, episode.start_pose, episode.seed)
        budget = action_budget(config, episode.route_length)
        # The building's grid is the robot's map of its walls where the world is built
        # from it; with the annotated walls the world is the rectangles, and so is its map.
        grid = building_grid(b, folder) if sim.walls == "grid" else None
        ctx = make_context(
            base, pm, config, seed=episode.seed, budget=budget, deferred_work=True, grid=grid
        )
        updates = None
        if out_dir is not None:
            out_dir.mkdir(parents=True, exist_ok=True)
            updates = out_dir / f"{safe_filename(episode.id)}{UPDATES_SUFFIX}"
            watch_map(ctx, UpdatesFile(updates, _building_ref(file, b.name)))
        truth: list[tuple[float, float, float]] = []

        def record(tree) -> None:
            p = inner.pose()
            truth.append((ctx.now(), p.x, p.y))
            if on_tick is not None:
                on_tick(tree)

        log_path = None
        if out_dir is not None:
            out_dir.mkdir(parents=True, exist_ok=True)
            log_path = out_dir / f"{safe_filename(episode.id)}.tree.jsonl"
        with open(log_path, "w", encoding="utf-8") if log_path else _null() as log:
            sinks = [s for s in (log, also_log) if s is not None]
            view = None  # no log, no view entries (nor frames encoded for them)
            if sinks:
                view = ViewRecorder(ctx, building=_building_ref(file, b.name), truth=inner.pose)
            outcome = run_tree(
                ctx, episode.goal, log=_Tee(sinks) if sinks else None, on_tick=record, view=view
            )
        final = inner.pose()
        stats = inner.stats
        people_contacts = world.people.contacts
    wall = time.perf_counter() - t0
    result = score_episode(
        pm,
        episode,
        (final.x, final.y),
        geodesic=geodesic,
        path_length=stats.path_length,
        steps=outcome.actions,
        collisions=stats.collisions,
        people_contacts=people_contacts,
        wall_time=wall,
        failure=None if outcome.success else str(outcome.failure),
        door=door,
    )
    plot_path = None
    if out_dir is not None and plot:
        plot_path = out_dir / f"{safe_filename(episode.id)}.trajectory.png"
        _plot(pm, ctx.trace, truth, plot_path, result, config, outcome, folder)
    return EpisodeRun(result, plot_path, log_path, updates)


def _building_ref(file: Path, name: str) -> str:
    """How a tree log names the building: a built-in by its name (the log stays readable
    on another machine), any other by its file's path."""
    from pmnav_bt.map.catalogue import builtin_buildings, resolve_building_path

    if name in builtin_buildings() and resolve_building_path(name).resolve() == file.resolve():
        return name
    return str(file)


class _null:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


class _Tee:
    """A text sink writing to several (the log file and the live view)."""

    def __init__(self, sinks: list[TextIO]) -> None:
        self.sinks = sinks

    def write(self, text: str) -> int:
        for s in self.sinks:
            s.write(text)
        return len(text)


def _plot(
    pm, trace, truth, path: Path, result: EpisodeResult, config: Config, outcome, base_dir="."
) -> None:
    """The Fig. 4-style plot: planned path, driven path, key nodes with thumbnails."""
    import numpy as np

    from pmnav_bt.render.trajectory import KeyNode, render_trajectory

    times = np.array([t for t, _, _ in truth]) if truth else np.zeros(1)

    def true_xy(t: float) -> tuple[float, float]:
        if not truth:
            return (0.0, 0.0)
        i = int(np.clip(np.searchsorted(times, t), 0, len(truth) - 1))
        return truth[i][1], truth[i][2]

    plans = [e for e in trace if e.kind == "plan"]
    planned = [tuple(p) for p in plans[-1].data["path"]] if plans else []
    nodes = [
        KeyNode(e.kind, e.label, true_xy(e.time), e.thumbnail)
        for e in trace
        if e.kind in ("fix", "detection", "corner", "obstacle", "arrive")
    ]
    verdict = "SUCCESS" if result.success else f"FAILED ({result.failure_reason})"
    caption = (
        f"{TREE_VARIANTS.spec(config.tree.variant).label} "
        f"[{grounder_label(config.grounder.backend)}]: {verdict}; "
        f"SPL {result.spl:.2f}; {result.path_length:.1f} m driven, "
        f"{result.shortest_path_length:.1f} m shortest; {outcome.actions} actions"
    )
    actual = [(x, y) for _, x, y in truth]
    render_trajectory(pm, planned, actual, nodes, path, caption, base_dir=base_dir)


# -- evaluation over many episodes ---------------------------------------------------------


def episodes_for(buildings: Iterable[str], tiers: Iterable[str], n: int, seed: int):
    """Generated episodes per building and tier; tiers a building cannot pose are skipped
    with a note. A site of several levels poses only cross_level (its one-level tiers are
    skipped with a note); a one-level building poses no cross_level: with other tiers
    asked for too (``--tier all``) it is skipped in silence, alone it is noted."""
    from pmnav_bt.eval.tiers import CROSS_LEVEL
    from pmnav_bt.experiments.site_run import site_of_levels
    from pmnav_bt.sim.episodes import EpisodeGenerationError, generate_episodes
    from pmnav_bt.sim.site_episodes import generate_site_episodes

    tiers = list(tiers)
    one_level_tiers = [t for t in tiers if t != CROSS_LEVEL]
    out, notes, flat = [], [], []
    for b in buildings:
        if site_of_levels(b):
            if one_level_tiers:
                notes.append(
                    f"{b} is a site of several levels: its episodes are {CROSS_LEVEL}, "
                    f"not {', '.join(one_level_tiers)}"
                )
            if CROSS_LEVEL in tiers:
                out += generate_site_episodes(b, n, seed=seed)
            continue
        if CROSS_LEVEL in tiers:
            flat.append(b)
        for tier in one_level_tiers:
            try:
                out += generate_episodes(b, tier, n, seed=seed)
            except EpisodeGenerationError as err:
                notes.append(str(err))
    if flat and not one_level_tiers:
        notes.append(
            f"no {CROSS_LEVEL} episodes in {', '.join(flat)}: one level each (a site of "
            "several levels, such as hospital_2l, poses them)"
        )
    return out, notes


def _error_result(episode, error: str) -> EpisodeResult:
    return EpisodeResult(
        episode_id=episode.id,
        tier=episode.tier,
        success=False,
        spl=0.0,
        path_length=0.0,
        steps=0,
        failure_reason=None,
        building=episode.building,
        route_length=episode.route_length,
        error=error,
    )


def _run_one(args) -> dict:
    """One episode in a worker (pool process or Ray task); a crash becomes an errored
    result (counted apart from navigation failures), not a lost run."""
    from pmnav_bt.experiments.site_run import run_site_episode
    from pmnav_bt.sim.site_episodes import SiteEpisode

    episode, config_json = args
    config = Config.model_validate_json(config_json)
    try:
        if isinstance(episode, SiteEpisode):  # across levels: its own world per level
            run = run_site_episode(episode, config)
        else:
            run = run_episode(episode, config, out_dir=None, plot=False)
    except Exception as err:  # noqa: BLE001 - reported in the results, with its type
        return _error_result(episode, f"{type(err).__name__}: {err}").to_dict()
    return run.result.to_dict()


def evaluate(
    episodes: list,
    configs: dict[str, Config],
    jobs: int = 1,
    progress: Callable[[str, int, int], None] | None = None,
    on_result: Callable[[str, EpisodeResult], None] | None = None,
    finished: dict[str, list[EpisodeResult]] | None = None,
    ray: str | None = None,
    done: dict[tuple[str, str], EpisodeResult] | None = None,
) -> dict[str, list[EpisodeResult]]:
    """Run every episode under each named config; results per config name, in episode
    order.

    ``done`` holds results already on disk, keyed (config name, episode id): those runs
    are skipped and their results included (``--resume``). ``on_result(name, result)`` is
    called as each new run ends (to save it at once); ``progress(name, done, total)``
    after it. ``finished``, when given, is filled as results arrive: after an
    interruption it holds what finished. Runs go to ``jobs`` pool processes, or to Ray
    (``ray``: "local" or a cluster address; see ``executors``); the same seeds give the
    same results either way.
    """
    from pmnav_bt.experiments.executors import TaskCrash, run_tasks

    done = done or {}
    results: dict[str, list[EpisodeResult]] = {} if finished is None else finished
    for name in configs:
        results.setdefault(name, []).extend(
            done[(name, e.id)] for e in episodes if (name, e.id) in done
        )
    todo = [(n, e) for n in configs for e in episodes if (n, e.id) not in done]
    total = len(episodes) * len(configs)
    count = total - len(todo)
    blobs = {n: c.model_dump_json() for n, c in configs.items()}
    payload = [(e, blobs[n]) for n, e in todo]
    try:
        for i, row in run_tasks(_run_one, payload, jobs=jobs, ray=ray):
            name, episode = todo[i]
            r = (
                _error_result(episode, row.message)
                if isinstance(row, TaskCrash)
                else EpisodeResult.from_dict(row)
            )
            results[name].append(r)
            if on_result:
                on_result(name, r)
            count += 1
            if progress:
                progress(name, count, total)
    finally:
        order = {e.id: i for i, e in enumerate(episodes)}
        for rs in results.values():
            rs.sort(key=lambda r: order.get(r.episode_id, 0))
    return results


def comparison_markdown(results: dict[str, list[EpisodeResult]]) -> str:
    """SR, SPL and soft SPL per tier, one column group per variant (like the paper's
    Table 1); an errors column when episodes could not be run."""
    from pmnav_bt.experiments.variants import variant_title

    tables = {name: aggregate_by_tier(rs) for name, rs in results.items()}
    tiers = []
    for t in tables.values():
        for row in t.rows:
            if row.tier not in tiers:
                tiers.append(row.tier)
    errors = any(r.errors for t in tables.values() for r in t.rows)
    metrics = ("SR", "SPL", "soft SPL") + (("errors",) if errors else ())
    head = (
        "| tier | n | "
        + " | ".join(f"{variant_title(n)} {m}" for n in tables for m in metrics)
        + " |"
    )
    sep = "|---|---|" + "---|" * (len(metrics) * len(tables))
    lines = [head, sep]
    for tier in tiers:
        cells, count = [], 0
        for t in tables.values():
            row = next((r for r in t.rows if r.tier == tier), None)
            if row is None:
                cells.append(" | ".join("-" for _ in metrics))
                continue
            count = max(count, row.episodes + row.errors)
            vals = [f"{row.sr:.1f}", f"{row.spl:.1f}", f"{row.soft_spl:.1f}"]
            cells.append(" | ".join(vals + ([str(row.errors)] if errors else [])))
        lines.append(f"| {tier} | {count} | " + " | ".join(cells) + " |")
    lines.append("")
    lines += [f"- {variant_title(name)}: {run_summary(rs)}" for name, rs in results.items()]
    return "\n".join(lines)


def failure_code(reason: str) -> str:
    """The code of a failure reason ("BUDGET_EXCEEDED: ..." -> BUDGET_EXCEEDED)."""
    head = reason.split(":", 1)[0].strip()
    return head if head.replace("_", "").isalpha() and head.isupper() else "OTHER"


def run_summary(results: list[EpisodeResult]) -> str:
    """Failure codes with their counts, episode wall time mean and p95, and the contacts:
    the robot's collisions (total and per 100 episodes) and its contacts with people."""
    import numpy as np

    codes: dict[str, int] = {}
    for r in results:
        if r.error is None and not r.success:
            c = failure_code(r.failure_reason or "")
            codes[c] = codes.get(c, 0) + 1
    fails = ", ".join(f"{c} {k}" for c, k in sorted(codes.items())) or "none"
    walls = [r.wall_time for r in results if r.error is None]
    wall = f"{np.mean(walls):.1f} s / {np.percentile(walls, 95):.1f} s" if walls else "-"
    c = contact_totals(results)
    return (
        f"failures: {fails}; episode wall time mean / p95: {wall}; "
        f"collisions: {c.collisions} ({c.per_100_text()} per 100 episodes); "
        f"people contacts: {c.people_text()}"
    )


def error_counts(results: dict[str, list[EpisodeResult]]) -> dict[str, int]:
    """Errored episodes per variant (only variants with errors)."""
    counts = {name: sum(r.error is not None for r in rs) for name, rs in results.items()}
    return {name: c for name, c in counts.items() if c}


def save_evaluation(results: dict[str, list[EpisodeResult]], out_dir: Path, header: str) -> Path:
    """Write results.json (every episode) and results.md (the table); return the .md path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    data = {name: [r.to_dict() for r in rs] for name, rs in results.items()}
    atomic_write_text(out_dir / "results.json", json.dumps(data, indent=1))
    md = out_dir / "results.md"
    atomic_write_text(md, header + "\n\n" + comparison_markdown(results) + "\n")
    return md


def variant_configs(base: Config, variants: Iterable[str]) -> dict[str, Config]:
    """One config per named evaluation variant (``pmnav_bt.experiments.variants``)."""
    from pmnav_bt.experiments.variants import variant_configs as _configs

    return _configs(base, variants)
