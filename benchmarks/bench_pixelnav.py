"""Inference latency of the PixelNav policy per step, on this machine's CPU.

One step is what the approach asks of the worker per frame: shrink the camera frame,
encode it, run the transformer over the history, read the heads (``PixelNavPolicy.act``).
A reset (goal encoding) is timed apart. Frames come from the simulator (fig2_hospital,
320x240, the tree's camera), taken once beforehand so that rendering is not timed.

Target (issue 10): p95 < 20 ms per step on CPU.

    python benchmarks/bench_pixelnav.py [--weights W.safetensors] [--steps 300] [--threads 1]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
import torch

from pmnav_bt.pixelnav.dataset import MAX_STEPS
from pmnav_bt.pixelnav.policy import PixelNavPolicy
from pmnav_bt.seams import Detection, Pose2D
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.world import SimWorld


def pct(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q * (len(xs) - 1) + 0.5))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", default="", help="default: the shipped small model")
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    policy = PixelNavPolicy.load(args.weights or None)
    with SimWorld("fig2_hospital") as world:
        base = SimBase(world, pose=Pose2D(0.0, 24.5, math.atan2(-2.5, 1.2)), width=320, height=240)
        frames = []
        for i in range(16):
            base.set_pose(Pose2D(0.0, 24.5 - 0.1 * i, math.atan2(-2.5, 1.2)))
            frames.append(base.observe())
        base.close()
    mask = np.zeros((240, 320), bool)
    mask[60:180, 200:240] = True
    goal = Detection("door", (200, 60, 239, 179), 1.0, mask=mask)
    resets, steps = [], []
    for i in range(args.steps + 20):
        if i % MAX_STEPS == 0:  # a new goal once the skill's budget is spent
            t = time.perf_counter()
            policy.reset(frames[0], goal)
            resets.append(time.perf_counter() - t)
        t = time.perf_counter()
        policy.act(frames[i % len(frames)])
        if i >= 20:  # warm-up
            steps.append(time.perf_counter() - t)
    ms = [s * 1000 for s in steps]
    cfg = policy.cfg
    print(
        f"PixelNav {cfg.width}x{cfg.height}, history {cfg.history}, dim {cfg.dim}, "
        f"{cfg.layers} layers; torch {torch.__version__}, {args.threads} thread(s), CPU"
    )
    print(
        f"step (act): p50 {statistics.median(ms):.2f} ms, p95 {pct(ms, 0.95):.2f} ms, "
        f"max {max(ms):.2f} ms over {len(ms)} steps (target p95 < 20 ms)"
    )
    print(f"reset (goal encoding): p50 {statistics.median(resets) * 1000:.2f} ms")


if __name__ == "__main__":
    main()
