"""Run one episode across levels in the simulator (``pmnav sim run`` on a site of several
levels): a world per level with the lifts' cabins, the robot carried between them by the
simulated lift system, the mission across levels (``trees/site.py``: the PM-Nav tree on
each level, for any tree variant that reads the map) ticked to its end, scored, and a
trajectory plot drawn per level.

Scoring: success is stopping within 1 m of the goal door on the goal level (and no
failure). SPL's shortest path is the free-space geodesic of each leg (the start, or a
lift's lobby on arrival, to the next lift's lobby, or on the last level to the goal's
success disc) and, per ride, the drive into the cabin and out again.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

from pmnav_bt.config import Config
from pmnav_bt.errors import PmNavError
from pmnav_bt.eval.metrics import EpisodeResult, soft_spl, spl, success
from pmnav_bt.loading import safe_filename
from pmnav_bt.sim.site_episodes import SiteEpisode, site_plan


@dataclass(frozen=True)
class SiteRun:
    """An episode's result and the files written for it: a trajectory plot per level."""

    result: EpisodeResult
    plots: dict[str, Path]
    tree_log: Path | None = None


def run_site_episode(ep: SiteEpisode, config: Config, out_dir: Path | None = None) -> SiteRun:
    """Run ``ep`` (see the module); write its tree log and plots to ``out_dir``."""
    from pmnav_bt.behaviours.lift import into_cabin
    from pmnav_bt.eval.geodesic import GeodesicField
    from pmnav_bt.sim.episodes import goal_door_in_world, goal_geodesic
    from pmnav_bt.sim.levels import LevelBody
    from pmnav_bt.sim.lift import SimLift
    from pmnav_bt.sim.odometry import NoisyOdometry
    from pmnav_bt.sim.robot import COLLISION_HEIGHT
    from pmnav_bt.sim.site_episodes import RIDE_ACTIONS, site_map, site_plan
    from pmnav_bt.sim.world import SimWorld
    from pmnav_bt.trees.lift import level_context
    from pmnav_bt.trees.runner import action_budget, make_context, run_tree
    from pmnav_bt.trees.site import build_site_tree, site_rides

    sm = site_map(ep.site)
    site = sm.site
    plan = site_plan(sm, ep)
    rides = site_rides(sm, plan)
    sim = config.sim
    t0 = time.perf_counter()
    worlds: dict[str, SimWorld] = {}
    grids = level_grids(site, config)
    try:
        level_worlds(site, config, ep.seed, worlds)
        body = LevelBody(
            worlds, ep.start_level, ep.start_pose, width=sim.width, height=sim.height,
            reading_width=sim.reading_width,
        )  # fmt: skip
        base = NoisyOdometry(body, sim.odometry_noise, seed=ep.seed) if sim.odometry_noise else body
        # Success is judged at the goal door the goal level's world hung (on a grid wall).
        door = goal_door_in_world(worlds[ep.goal_level], sm.maps[ep.goal_level], ep.goal)
        rng = worlds[ep.start_level].rng("lift")
        lift = SimLift(body.clock, body, rng, config.world.lift_full_p)
        for link in site.lifts:
            order = sorted(link.lobbies, key=site.rank)
            cabins = {lv: worlds[lv].cabins[link.lobbies[lv]] for lv in order}
            lift.add(link.id, link.display_name, cabins, order[-1])
        # SPL's shortest path: each leg's geodesic, and each ride's drive in and out.
        shortest, at = 0.0, (ep.start_x, ep.start_y)
        for i, leg in enumerate(plan.legs):
            w = worlds[leg.level]
            feet = w.obstacle_footprints(COLLISION_HEIGHT)
            if i < len(rides):
                field = GeodesicField(w.floor_space(), rides[i].board.lobby, 0.3, obstacles=feet)
                shortest += field.distance(at) + 2 * into_cabin(rides[i].board)
                at = rides[i].alight.lobby
            else:
                pm = sm.maps[leg.level]
                geodesic = goal_geodesic(pm, ep.goal, feet, floor=w.floor_space(), door=door)
                shortest += geodesic.distance(at)
        pm0 = sm.maps[ep.start_level]
        budget = action_budget(config, ep.route_length) + RIDE_ACTIONS * ep.rides
        ctx = make_context(
            base, pm0, config, seed=ep.seed, budget=budget, deferred_work=True,
            grid=grids[ep.start_level],
        )  # fmt: skip
        contexts = {ep.start_level: ctx}
        for name, pm in sm.maps.items():
            if name != ep.start_level:
                contexts[name] = level_context(ctx, pm, ep.seed, grid=grids[name])
        truth: list[tuple[float, str, float, float]] = []

        def record(tree) -> None:
            p = body.world_pose()
            truth.append((ctx.now(), body.level, p.x, p.y))

        log_path = None
        if out_dir is not None:
            out_dir.mkdir(parents=True, exist_ok=True)
            log_path = out_dir / f"{safe_filename(ep.id)}.tree.jsonl"
        with open(log_path, "w", encoding="utf-8") if log_path else _Null() as log:
            outcome = run_tree(
                ctx, plan.goal, log=log, on_tick=record,
                build=lambda c, g: build_site_tree(contexts, sm, plan, lift),
                ended_on=lambda: contexts[body.level],
            )  # fmt: skip
        final, level, stats = body.world_pose(), body.level, body.stats
        contacts = sum(w.people.contacts for w in worlds.values())
        full_calls = lift.full_calls
        lift.close()
        body.close()
    finally:
        for w in worlds.values():
            w.close()
    stop = (final.x, final.y)
    dist = math.dist(stop, door) if level == ep.goal_level else math.inf
    ok = outcome.success and level == ep.goal_level and success(stop, door)
    reason = None if outcome.success else str(outcome.failure)
    if reason is None and not ok:
        reason = f"STOPPED_AWAY: stopped {dist:.2f} m from the door on level {level}"
    result = EpisodeResult(
        episode_id=ep.id,
        tier=ep.tier,
        success=ok,
        spl=spl(ok, shortest, stats.path_length),
        path_length=stats.path_length,
        steps=outcome.actions,
        collisions=stats.collisions,
        people_contacts=contacts,
        wall_time=time.perf_counter() - t0,
        failure_reason=reason,
        shortest_path_length=shortest,
        distance_to_goal=0.0 if ok else float("nan"),
        building=ep.site,
        soft_spl=float("nan") if not ok else soft_spl(shortest, 0.0, stats.path_length),
        distance_to_door=dist,
        route_length=ep.route_length,
        rides=ep.rides,
        lifts_full=full_calls,
    )
    plots: dict[str, Path] = {}
    if out_dir is not None:
        plots = _plots(sm, ep, ctx.trace, truth, result, out_dir)
    return SiteRun(result, plots, log_path)


def level_grids(site, config: Config) -> dict:
    """Each level's occupancy grid where its world is built from it (``sim.walls=grid``):
    the robot's map of that level's walls, as in a one-level episode
    (``evaluation.run_episode``); None per level otherwise."""
    from pmnav_bt.pose.evidence.floor_model import building_grid

    if config.sim.walls != "grid":
        return {lv.name: None for lv in site.levels}
    return {lv.name: building_grid(lv.building, _folder(lv)) for lv in site.levels}


def level_worlds(site, config: Config, seed: int, into: dict) -> dict:
    """A world per level of ``site`` into ``into`` (level name -> ``SimWorld``, so a
    caller can close the ones made when a later one fails): walls as ``sim.walls`` says,
    a cabin behind each of its lifts' lobbies."""
    from pmnav_bt.sim.world import SimWorld

    for lv in site.levels:
        lobbies = {lift.lobbies[lv.name] for lift in site.lifts_at(lv.name)}
        into[lv.name] = SimWorld(
            lv.building, walls=config.sim.walls, base_dir=_folder(lv) if lv.path else None,
            scene=config.world, seed=seed, lifts=lobbies,
        )  # fmt: skip
    return into


def _folder(lv) -> Path:
    """The folder a level's floor plan path is relative to: its building file's."""
    return lv.path.parent if lv.path else Path(".")


CABIN_COLOUR = (40, 40, 40)  # BGR: the lift cabin's outline on a level's plot


def _plots(sm, ep: SiteEpisode, trace, truth, result, out_dir: Path) -> dict[str, Path]:
    """A trajectory plot per level the robot was on: its path there (truth), the leg's
    plan on that level, the events seen there (a trace event is on the level of the last
    ``level`` event before it) and the outline of the cabins it rode in."""
    import cv2
    import numpy as np

    from pmnav_bt.render.annotate import make_canvas
    from pmnav_bt.render.trajectory import KeyNode, render_trajectory
    from pmnav_bt.trees.site import site_rides

    doorways: dict[str, list] = {}
    for r in site_rides(sm, site_plan(sm, ep)):
        doorways.setdefault(r.from_level, []).append(r.board)
        doorways.setdefault(r.to_level, []).append(r.alight)

    times = np.array([t for t, *_ in truth]) if truth else np.zeros(1)
    level, on_level = ep.start_level, []
    for e in trace:
        if e.kind == "level":
            level = e.label
        on_level.append((level, e))
    plots = {}
    verdict = "SUCCESS" if result.success else f"FAILED ({result.failure_reason})"
    for name in dict.fromkeys(lv for _, lv, _, _ in truth):
        path_xy = [(x, y) for _, lv, x, y in truth if lv == name]
        plans = [e for lv, e in on_level if lv == name and e.kind == "plan"]
        planned = [tuple(p) for p in plans[-1].data["path"]] if plans else []

        def at(t: float) -> tuple[float, float]:
            i = int(np.clip(np.searchsorted(times, t), 0, len(truth) - 1))
            return truth[i][2], truth[i][3]

        nodes = [
            KeyNode(e.kind, e.label, at(e.time), e.thumbnail)
            for lv, e in on_level
            if lv == name and e.kind in ("fix", "detection", "corner", "obstacle", "arrive")
        ]
        caption = (
            f"{ep.id}: level {name} of {ep.site} ({ep.start_level} -> {ep.goal} on "
            f"{ep.goal_level}): {verdict}; SPL {result.spl:.2f}"
        )
        out = out_dir / f"{safe_filename(ep.id)}.{safe_filename(name)}.trajectory.png"
        img = render_trajectory(
            sm.maps[name], planned, path_xy, nodes, None, caption,
            base_dir=_folder(sm.site.level(name)),
        )  # fmt: skip
        canvas = make_canvas(sm.maps[name])
        for d in doorways.get(name, ()):  # the cabins ridden from or to, behind the wall
            pts = np.rint(canvas.to_px(d.cabin_corners())).astype(np.int32)
            cv2.polylines(img, [pts], True, CABIN_COLOUR, 2, cv2.LINE_AA)
        if not cv2.imwrite(str(out), img):
            raise OSError(f"could not write {out}")
        plots[name] = out
    return plots


class _Null:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


def site_of_levels(name: str) -> bool:
    """Whether ``name`` (a path or a built-in name) is a site of several levels."""
    from pmnav_bt.map.site import load_site

    return len(load_site(name).levels) > 1


def run_site(name: str, goal: str, start: str | None, seed: int, config: Config, out: Path) -> None:
    """``pmnav sim run`` in a site of several levels: one episode to ``goal``, printed."""
    from pmnav_bt.sim.site_episodes import custom_site_episode

    show_site_run(custom_site_episode(name, goal, start, seed), config, out)


def show_site_run(ep: SiteEpisode, config: Config, out: Path) -> None:
    """Run one episode across levels (``pmnav sim run``: to a goal, or a stored one from
    ``--episodes``) and print it."""
    import typer

    from pmnav_bt.registry import grounder_label
    from pmnav_bt.tree_variants import TREE_VARIANTS

    spec = TREE_VARIANTS.spec(config.tree.variant)
    if not spec.knows.plans:
        raise PmNavError(
            f"tree.variant {config.tree.variant} reads no map: it cannot plan across levels"
        )
    typer.echo(
        f"{spec.label} [{grounder_label(config.grounder.backend)}] in {ep.site}: {ep.id} "
        f"({ep.tier}), start on {ep.start_level} ({ep.start_x:.1f}, "
        f"{ep.start_y:.1f}, {math.degrees(ep.start_yaw):.0f} deg), goal {ep.goal} on "
        f"{ep.goal_level}, {ep.rides} ride(s), corridor route {ep.route_length:.1f} m"
    )
    r = run_site_episode(ep, config, out)
    res = r.result
    typer.echo(
        f"{'SUCCESS' if res.success else 'FAILURE'}: SPL {res.spl:.3f}, {res.steps} actions, "
        f"{res.path_length:.1f} m driven (shortest {res.shortest_path_length:.1f} m), "
        f"{res.collisions} collisions, stopped {res.distance_to_door:.2f} m from the door, "
        f"{res.wall_time:.1f} s wall"
    )
    if res.failure_reason:
        typer.echo(f"reason: {res.failure_reason}")
    typer.echo(f"tree log: {r.tree_log}")
    for level, plot in r.plots.items():
        typer.echo(f"trajectory plot, level {level}: {plot}")
    if not res.success:
        raise typer.Exit(1)
