"""Tick latency of the PM-Nav tree while a VLM call hangs.

A local chat server accepts every request and never answers. The tree runs in the
simulator at 10 Hz of real time with the robot's worker mode (``immediate``: jobs run in
a worker thread during ticks), with a ``vlm`` back end pointing at that server:

- ``--stage plan`` (default): the planner. The call ends after ``vlm.timeout_s`` with the
  graph fallback, or, with ``--no-fallback``, VLM_ERROR (the tree replans, then fails);
- ``--stage coarse``: the coarse direction (graph planner); each call ends with
  VLM_ERROR after the timeout. Needs the CoarseDirection behaviour that calls the back
  end in the worker (the seams migration).

Target (docs/architecture.md, a tick never blocks): p99 tick < 5 ms while a call hangs.

    python benchmarks/bench_vlm_tick.py [--stage plan|coarse] [--timeout 3] [--no-fallback]
"""

from __future__ import annotations

import argparse
import statistics
import time

from pmnav_bt.config import load_config
from pmnav_bt.experiments.evaluation import custom_episode
from pmnav_bt.seams import PlanConstraints
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.planner import VlmPlanner
from pmnav_bt.vlm.scripted_server import ChatServer, Reply


class _Planner:
    """The VLM planner, accepting both the constraint object and the older keyword form
    of MakePlan (until every caller passes PlanConstraints)."""

    def __init__(self, inner: VlmPlanner):
        self.inner = inner

    def plan(self, pm, start, goal, constraints=None, avoid_landmarks=(), blocked_segments=()):
        c = constraints or PlanConstraints(frozenset(avoid_landmarks), frozenset(blocked_segments))
        return self.inner.plan(pm, start, goal, c)


def pct(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q * (len(xs) - 1) + 0.5))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stage", choices=("plan", "coarse"), default="plan")
    ap.add_argument("--timeout", type=float, default=3.0, help="vlm.timeout_s, seconds")
    ap.add_argument("--no-fallback", action="store_true", help="fail with VLM_ERROR")
    ap.add_argument("--max-seconds", type=float, default=60.0, help="wall time to run at most")
    args = ap.parse_args()

    import py_trees

    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.sim.robot import SimBase
    from pmnav_bt.sim.world import SimWorld
    from pmnav_bt.trees.pmnav import build_pmnav_tree
    from pmnav_bt.trees.runner import make_context

    cfg = load_config()
    ep = custom_episode("fig2_hospital", "room17", "22,0,0")
    b = load_building(ep.building)
    pm = parse_building(b)
    hang = ChatServer(lambda req: Reply("", delay_s=3600.0)).start()
    requested: list[float] = []
    inner_responder = hang.responder

    def note(req):
        requested.append(time.perf_counter())
        return inner_responder(req)

    hang.responder = note
    client = VlmClient(hang.base_url, "hang", timeout_s=args.timeout, retries=0)
    planner = VlmPlanner(client, fallback=not args.no_fallback, tries=1)
    ticks: list[tuple[float, float]] = []  # (start, duration)
    with SimWorld(b) as world:
        base = SimBase(
            world,
            pose=ep.start_pose,
            width=cfg.sim.width,
            height=cfg.sim.height,
            reading_width=cfg.sim.reading_width,
        )
        ctx = make_context(base, pm, cfg, seed=0, budget=2000, deferred_work=False)
        coarse = None
        if args.stage == "plan":
            ctx.planner = _Planner(planner)
        else:
            from pmnav_bt.vlm.coarse import VlmCoarseDirection

            coarse = VlmCoarseDirection(client, pm.building, ctx.grounder)
            ctx.coarse = coarse
        py_trees.blackboard.Blackboard.clear()
        tree = build_pmnav_tree(ctx, ep.goal)
        tree.setup()
        t_end = time.perf_counter() + args.max_seconds
        status = py_trees.common.Status.RUNNING
        while time.perf_counter() < t_end and status == py_trees.common.Status.RUNNING:
            t0 = time.perf_counter()
            tree.tick()
            ticks.append((t0, time.perf_counter() - t0))
            status = tree.root.status
            hang_over = requested and t0 > requested[0] + args.timeout + 1
            if hang_over and args.stage == "plan" and planner.stats.plans and not args.no_fallback:
                break  # the graph's plan took over: the tree drives on
            base.clock.wait(0.1)
            time.sleep(max(0.0, 0.1 - (time.perf_counter() - t0)))
        tree.interrupt()
        ctx.worker.shutdown()
        failure = py_trees.blackboard.Blackboard.storage.get("/pmnav/failure")
    hang.stop()
    if not requested:
        raise SystemExit(f"the {args.stage} back end never called the server")
    t_req = requested[0]
    during = [1e3 * d for t, d in ticks if any(r <= t <= r + args.timeout for r in requested)]
    allms = [1e3 * d for _, d in ticks]
    plan = py_trees.blackboard.Blackboard.storage.get("/pmnav/plan")
    print(
        f"{len(requested)} VLM {args.stage} call(s), each hanging for {args.timeout:g} s "
        "(vlm.timeout_s); tree at 10 Hz real time, immediate worker (the robot's mode), "
        "fig2_hospital, goal room17"
    )
    print(f"{'ticks':<28} {'n':>5} {'median ms':>9} {'p99 ms':>7} {'max ms':>7}")
    for name, xs in (("while the call hangs", during), ("whole run", allms)):
        print(
            f"{name:<28} {len(xs):>5} {statistics.median(xs):>9.3f} {pct(xs, 0.99):>7.2f} "
            f"{max(xs):>7.2f}"
        )
    k = max(range(len(ticks)), key=lambda i: ticks[i][1])
    print(
        f"slowest tick: #{k + 1} of {len(ticks)}, {ticks[k][0] - t_req:+.2f} s from the request "
        f"(the first call hangs from 0 to {args.timeout:g} s)"
    )
    if args.stage == "plan":
        print(f"planner: {planner.stats.to_dict()}")
    if plan is not None and args.stage == "plan":
        print(f"plan: {plan.planner}; {plan.notes[-1]}")
    print(f"tree status: {status.value}; failure: {failure}")
    print("target: p99 tick < 5 ms while the call hangs")


if __name__ == "__main__":
    main()
