"""Simulator speed: camera frames per second, sim steps per second, building load times,
and what the config's world preset costs (issue 36: realistic at most 1.5x clean).

Run: python benchmarks/bench_sim.py [--frames 60] [--building fig2_hospital]
         [--part all|speed|presets] [--presets clean,realistic] [--episodes 1]
         [--set world.people_per_100m=0 ...]
Targets: >= 20 frames/s at 320x240 (RGB + depth + segmentation) on 2 CPU cores; the
realistic preset's episode CPU time at most 1.5x the clean preset's.

The preset part measures CPU time (``time.process_time``: every thread of the process,
so a loaded machine's waiting does not count) per preset, the presets interleaved episode
by episode so both see the same machine:

- views: a world built per building and seed (the build counted), then a scripted walk
  of the robot's camera (the sim config's size, RGB + depth + segmentation, a reading
  crop of a plate's size per frame), a third of the frames taken while turning;
- episodes: whole episodes (``run_episode``: the tree, the grounder, the simulator) on a
  hospital, a school and an office, easy and medium tiers. The grounder is the oracle
  (``sim_gt``) unless ``--set grounder.backend=...`` says otherwise: the simulator's
  share of the episode is then largest, so the ratio is the least forgiving.

The presets are taken from the config as they stand (every knob at its preset default
unless ``--set`` overrides it), so the figures follow whatever the presets fill a world
with.
"""

from __future__ import annotations

import argparse
import math
import time

from pmnav_bt.config import Config, load_config
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.seams import DiscreteAction, MotionStatus, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import RADIUS, SimBase
from pmnav_bt.sim.world import SimWorld

TARGET_FPS_320 = 20.0
TARGET_PRESET_RATIO = 1.5  # realistic / clean episode CPU time (issue 36)
PRESET_BUILDINGS = ("fig2_hospital", "loop_school", "u_office")  # one per palette
PRESET_TIERS = ("easy", "medium")
VIEW_SEEDS = (0, 1)
VIEW_FRAMES = 30  # per building and seed
READING_BOX = (240, 200, 400, 260)  # a plate-sized crop of the 640-wide reading view


def bench_fps(world: SimWorld, width: int, height: int, frames: int, **flags) -> float:
    """Frames per second of SimBase.render_view, turning 30 deg between frames."""
    base = SimBase(world, SimClock(), width=width, height=height, **flags)
    base.observe()  # warm up
    t0 = time.perf_counter()
    for k in range(frames):
        base.render_view(k * math.pi / 6)
    dt = time.perf_counter() - t0
    base.close()
    return frames / dt


def _beside_a_wall(world: SimWorld, gap: float) -> Pose2D:
    """A pose mid-way along the longest corridor, ``gap`` metres from its wall, facing along it."""
    b = world.building
    e = max(b.edges, key=lambda e: math.dist(b.waypoint(e.a).pos, b.waypoint(e.b).pos))
    (ax, ay), (bx, by) = b.waypoint(e.a).pos, b.waypoint(e.b).pos
    length = math.dist((ax, ay), (bx, by))
    dx, dy = (bx - ax) / length, (by - ay) / length
    off = b.edge_width(e) / 2.0 - RADIUS - gap
    return Pose2D(
        ax + dx * length / 2 - dy * off, ay + dy * length / 2 + dx * off, math.atan2(dy, dx)
    )


def bench_ticks(world: SimWorld, pose: Pose2D, runs: int = 200) -> float:
    """Clock ticks per second while driving 1 s (0.3 m) from ``pose``, ``runs`` times."""
    clock = SimClock()
    base = SimBase(world, clock, width=32, height=24)
    t0 = time.perf_counter()
    for _ in range(runs):
        base.set_pose(pose)
        base.set_velocity(0.3, 0.0)
        clock.wait(1.0)
        if base.motion_status() != MotionStatus.MOVING:
            raise RuntimeError(f"the benchmark drive from {pose} was blocked")
    dt = time.perf_counter() - t0
    base.close()
    return runs / clock.tick / dt


def bench_actions(world: SimWorld) -> float:
    """Discrete actions (forward, left, right), each executed to its end, per second."""
    base = SimBase(world, SimClock(), width=32, height=24)
    actions = [DiscreteAction.FORWARD, DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT] * 20
    t0 = time.perf_counter()
    for a in actions:
        base.execute(a)
    rate = len(actions) / (time.perf_counter() - t0)
    base.close()
    return rate


def preset_config(preset: str, sets: list[str]) -> Config:
    """The config of one preset: the oracle grounder, then the user's ``--set`` overrides."""
    return load_config(None, ["grounder.backend=sim_gt", f"world.preset={preset}", *sets])


def view_cpu(config: Config, building: str, seed: int) -> tuple[float, float]:
    """CPU seconds to build ``building``'s world for ``seed`` and to take ``VIEW_FRAMES``
    frames walking and turning through it (a reading crop with each)."""
    sim = config.sim
    t0 = time.process_time()
    world = SimWorld(building, walls=sim.walls, scene=config.world, seed=seed)
    t1 = time.process_time()
    base = SimBase(
        world, SimClock(), width=sim.width, height=sim.height, reading_width=sim.reading_width
    )
    for k in range(VIEW_FRAMES):
        if k % 3 == 2:
            base.set_velocity(0.0, 1.0)  # a frame while turning (motion blur, if any)
        obs = base.observe()
        if obs.reading is not None:
            obs.reading.crop(READING_BOX)
        base.stop()
        if base.execute(DiscreteAction.FORWARD if k % 3 else DiscreteAction.TURN_LEFT) != (
            MotionStatus.IDLE
        ):
            base.execute(DiscreteAction.TURN_LEFT)
    t2 = time.process_time()
    base.close()
    world.close()
    return t1 - t0, t2 - t1


def bench_presets(presets: list[str], sets: list[str], episodes: int) -> None:
    """The preset part: per-preset CPU of built views and of whole episodes, and the ratio."""
    from pmnav_bt.experiments.evaluation import episodes_for, run_episode

    configs = {name: preset_config(name, sets) for name in presets}
    build = {name: 0.0 for name in presets}
    frames = {name: 0.0 for name in presets}
    for b in PRESET_BUILDINGS:
        for seed in VIEW_SEEDS:
            for name, cfg in configs.items():
                t_build, t_frames = view_cpu(cfg, b, seed)
                build[name] += t_build
                frames[name] += t_frames
    n_worlds = len(PRESET_BUILDINGS) * len(VIEW_SEEDS)
    n_frames = n_worlds * VIEW_FRAMES
    print(f"world preset cost, views ({n_worlds} worlds, {VIEW_FRAMES} frames each, CPU time):")
    for name in presets:
        print(
            f"  {name:<10} build {build[name] / n_worlds * 1000:7.1f} ms/world, "
            f"{frames[name] / n_frames * 1000:6.1f} ms/frame (with its step and reading crop)"
        )
    if episodes <= 0:
        return
    eps, notes = episodes_for(PRESET_BUILDINGS, PRESET_TIERS, episodes, seed=0)
    for note in notes:
        print(f"  note: {note}")
    cpu = {name: 0.0 for name in presets}
    actions = {name: 0 for name in presets}
    wins = {name: 0 for name in presets}
    for ep in eps:
        for name, cfg in configs.items():
            t0 = time.process_time()
            result = run_episode(ep, cfg, plot=False).result
            cpu[name] += time.process_time() - t0
            actions[name] += result.steps
            wins[name] += int(result.success)
    grounder = next(iter(configs.values())).grounder.backend
    print(f"world preset cost, episodes ({len(eps)} per preset, grounder {grounder}, CPU time):")
    for name in presets:
        print(
            f"  {name:<10} {cpu[name] / len(eps):6.2f} s/episode, "
            f"{cpu[name] / max(1, actions[name]) * 1000:6.1f} ms/action, "
            f"{wins[name]}/{len(eps)} succeeded"
        )
    if "clean" in cpu and "realistic" in cpu and cpu["clean"] > 0:
        ratio = cpu["realistic"] / cpu["clean"]
        per_action = (cpu["realistic"] / max(1, actions["realistic"])) / (
            cpu["clean"] / max(1, actions["clean"])
        )
        verdict = "OK" if ratio <= TARGET_PRESET_RATIO else f"ABOVE TARGET {TARGET_PRESET_RATIO:g}"
        print(
            f"  realistic / clean: {ratio:.2f}x per episode, {per_action:.2f}x per action  "
            f"{verdict}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--building", default="fig2_hospital")
    ap.add_argument("--part", choices=("all", "speed", "presets"), default="all")
    ap.add_argument("--presets", default="clean,realistic", help="comma-separated presets")
    ap.add_argument(
        "--episodes", type=int, default=1, help="episodes per building and tier (0: views only)"
    )
    ap.add_argument(
        "--set", action="append", default=[], dest="sets", help="config override KEY=VALUE"
    )
    args = ap.parse_args()
    if args.part in ("all", "presets"):
        bench_presets(args.presets.split(","), args.sets, args.episodes)
    if args.part == "presets":
        return

    print("building load time (SimWorld from a parsed Building):")
    for name in builtin_buildings():
        b = load_building(name)
        t0 = time.perf_counter()
        w = SimWorld(b)
        dt = time.perf_counter() - t0
        print(
            f"  {name:<16} {dt * 1000:7.1f} ms  ({len(w.walls)} wall segments, "
            f"{len(b.rooms)} rooms, {len(b.landmarks)} landmarks)"
        )
        w.close()

    with SimWorld(args.building) as world:
        print(f"camera frames per second ({args.building}, tiny renderer, 60 deg HFOV):")
        for w, h in ((320, 240), (640, 480)):
            full = bench_fps(world, w, h, args.frames)
            rgb = bench_fps(world, w, h, args.frames, depth=False, segmentation=False)
            note = ""
            if (w, h) == (320, 240):
                note = "  OK" if full >= TARGET_FPS_320 else f"  BELOW TARGET {TARGET_FPS_320:g}"
            print(f"  {w}x{h}: {full:6.1f} fps RGB+depth+seg, {rgb:6.1f} fps RGB only{note}")
        open_ticks = bench_ticks(world, _beside_a_wall(world, gap=0.5))
        wall_ticks = bench_ticks(world, _beside_a_wall(world, gap=0.02))
        acts = bench_actions(world)
        print("sim steps per second (1/60 s clock ticks with kinematic motion + collision check):")
        print(f"  {open_ticks:9.0f} ticks/s driving in the open ({open_ticks / 60:.0f}x real time)")
        rt = wall_ticks / 60
        print(f"  {wall_ticks:9.0f} ticks/s driving 2 cm from a wall ({rt:.0f}x real time)")
        print(f"  {acts:9.1f} discrete actions/s (forward/turn, executed to the end)")


if __name__ == "__main__":
    main()
