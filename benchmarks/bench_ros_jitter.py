"""cmd_vel jitter while perception runs: the period of the controller's velocity commands.

Starts ``pmnav-sim-create3`` and ``pmnav-ros`` as separate processes (Fast DDS on the
loopback, ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, a private ROS_DOMAIN_ID), runs
PM-Nav episodes (panoramic capture, grounding, localization, driving: perception
runs in the controller's worker thread while the heartbeat publishes cmd_vel), and
records every cmd_vel message in a third process. The period is measured between
consecutive *motion* commands (both non-zero: the robot moving), three ways:

- ``received``: the DDS reception time stamped by the middleware in the subscriber
  (rclpy MessageInfo ``received_timestamp``): what a C++ subscriber such as the
  Create 3's base driver sees. This is the figure the target applies to.
- ``source``: the DDS write time in the controller (``source_timestamp``).
- ``callback``: when the (Python, busy) probe's callback ran: adds the probe's own
  scheduling delays, an upper bound.

``--view``: the controller serves its live web view (``view_port``) with a page attached
to its event stream (``bench_tree.attach_page``), to see what a viewer costs cmd_vel.

Run: python benchmarks/bench_ros_jitter.py [--episodes easy:0,medium:1] [--width 320] [--view]
Target (cmd_rate_hz 20): p99 of the period < 75 ms; no gap over 0.5 s (the Create 3
stops after 0.5 s without a command).
"""

from __future__ import annotations

import argparse
import math
import os
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

TARGET_P99_MS = 75.0
BUILDING = "fig2_hospital"


def _periods(times: list[float], moving: list[bool]) -> np.ndarray:
    """Milliseconds between consecutive motion commands."""
    pairs = zip(times, times[1:], moving, moving[1:], strict=False)
    out = [t1 - t0 for t0, t1, m0, m1 in pairs if m0 and m1]
    return np.asarray(out, float) * 1000.0


def _row(name: str, per: np.ndarray) -> str:
    if not len(per):
        return f"{name:36s} {0:5d}"
    return (
        f"{name:36s} {len(per):5d} {np.median(per):7.1f} {np.percentile(per, 90):6.1f} "
        f"{np.percentile(per, 99):6.1f} {per.max():6.1f}"
    )


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", default="easy:0,medium:1", help="tier:index,... (seed 0)")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--camera-hz", type=float, default=5.0)
    ap.add_argument("--timeout", type=float, default=180.0, help="seconds per episode")
    ap.add_argument("--view", action="store_true", help="serve the web view, a page attached")
    args = ap.parse_args()

    from pmnav_bt.hardware.env import domain_id_for, rclpy_available

    ok, why = rclpy_available()
    if not ok:
        print(f"bench_ros_jitter: skipped: {why}")
        return 0
    domain = domain_id_for(os.getpid())
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

    from pmnav_bt.hardware.runtime import RosRuntime
    from pmnav_bt.hardware.testing import Probe, Proc
    from pmnav_bt.sim.episodes import generate_episodes

    rt = RosRuntime(args=[], domain_id=domain)
    probe = Probe(rt)
    rt.start()
    logs = Path(tempfile.mkdtemp(prefix="bench_ros_jitter_"))
    series: dict[str, list[np.ndarray]] = {"received": [], "source": [], "callback": []}
    print(
        f"cmd_vel period while PM-Nav runs: camera {args.width}x{args.height} at "
        f"{args.camera_hz} Hz, cmd_rate_hz 20, ROS_DOMAIN_ID {domain}; "
        f"web view: {'on, a page attached' if args.view else 'off'}; logs in {logs}"
    )
    print(f"{'':36s} {'n':>5s} {'median':>7s} {'p90':>6s} {'p99':>6s} {'max':>6s}  (ms)")
    try:
        for spec in args.episodes.split(","):
            tier, idx = spec.split(":")
            ep = generate_episodes(BUILDING, tier, int(idx) + 1, seed=0)[int(idx)]
            pose = f"{ep.start_x},{ep.start_y},{math.degrees(ep.start_yaw)}"
            sim = Proc(
                "pmnav_bt.hardware.sim_create3",
                {
                    "building": BUILDING,
                    "start_pose": pose,
                    "seed": ep.seed,
                    "width": args.width,
                    "height": args.height,
                    "camera_rate_hz": args.camera_hz,
                },
                domain,
                logs / f"{ep.id}-sim.log",
            )
            params = {"building": BUILDING, "seed": ep.seed, "budget": ep.step_budget}
            if args.view:
                params["view_port"] = view_port = _free_port()
            ctl = Proc("pmnav_bt.hardware.node", params, domain, logs / f"{ep.id}-controller.log")
            procs = (sim, ctl)
            page_stop = threading.Event()
            if args.view:
                from bench_tree import attach_page

                threading.Thread(
                    target=attach_page, args=(("127.0.0.1", view_port), page_stop), daemon=True
                ).start()
            try:
                with probe.lock:
                    probe.status = None
                probe.wait_for(
                    lambda: probe.status is not None and probe.status["fault"] is None,
                    60.0,
                    "ready",
                    procs,
                )
                with probe.lock:
                    probe.cmd.clear()
                    probe.cmd_dds.clear()
                t0 = time.monotonic()
                probe.send_goal(ep.goal)
                r = probe.wait_for(
                    lambda g=ep.goal: next((x for x in probe.results if x["goal"] == g), None),
                    args.timeout,
                    "result",
                    procs,
                )
                dt = time.monotonic() - t0
                with probe.lock:
                    cmds = list(probe.cmd)
                    dds = list(probe.cmd_dds)
                    probe.results.clear()
            finally:
                page_stop.set()
                for p in procs:
                    p.stop()
            moving = [bool(v or w) for _, v, w in cmds]
            per = {
                "received": _periods([d[1] for d in dds], moving),
                "source": _periods([d[0] for d in dds], moving),
                "callback": _periods([c[0] for c in cmds], moving),
            }
            res = "success" if r["success"] else r["code"]
            print(f"{ep.id} ({ep.goal}): {res} in {dt:.1f} s")
            for k, v in per.items():
                series[k].append(v)
                print(_row(f"  {k}", v))
    finally:
        rt.shutdown()
    print("all episodes")
    for k, v in series.items():
        print(_row(f"  {k}", np.concatenate(v)))
    per = np.concatenate(series["received"])
    p99 = float(np.percentile(per, 99))
    print(
        f"received: {int((per > TARGET_P99_MS).sum())} of {len(per)} periods > "
        f"{TARGET_P99_MS:.0f} ms, {int((per > 500).sum())} > 500 ms"
    )
    verdict = "meets" if p99 < TARGET_P99_MS else "MISSES"
    print(f"p99 {p99:.1f} ms (received) {verdict} the target (< {TARGET_P99_MS:.0f} ms)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
