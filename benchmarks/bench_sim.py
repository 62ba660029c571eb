"""Simulator speed: camera frames per second, sim steps per second, building load times.

Run: python benchmarks/bench_sim.py [--frames 60] [--building fig2_hospital]
Target: >= 20 frames/s at 320x240 (RGB + depth + segmentation) on 2 CPU cores.
"""

from __future__ import annotations

import argparse
import math
import time

from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.seams import DiscreteAction, MotionStatus, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import RADIUS, SimBase
from pmnav_bt.sim.world import SimWorld

TARGET_FPS_320 = 20.0


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--building", default="fig2_hospital")
    args = ap.parse_args()

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
