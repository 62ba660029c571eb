"""Episodes in the simulator with the graph planner and with the ``vlm`` planner behind a
scripted server that answers 30 % wrong plans: the validator, re-prompts and the graph
fallback keep the success rate of the graph planner, and the repairs and fallbacks are
counted.

The scripted server (``pmnav_bt.vlm.scripted_server``) computes each correct plan with the
graph planner and corrupts ``--wrong`` of its answers (wrong landmark, unconnected step,
wrong turn, wrong goal, prose, truncated JSON); its figures prove the plumbing, not a
model. Without ``--endpoint`` it runs in this process.

    python benchmarks/vlm_sim_eval.py [-n 1] [--tier all] [--building all] [--wrong 0.3]
"""

from __future__ import annotations

import argparse
import inspect
import json
import time
from pathlib import Path

from pmnav_bt.config import load_config
from pmnav_bt.experiments.evaluation import episodes_for
from pmnav_bt.seams import PlanConstraints
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.planner import VlmPlanner
from pmnav_bt.vlm.scripted_server import ChatServer, PlanningResponder


class _Planner:
    """A planner accepting both the constraint object and MakePlan's older keyword form."""

    def __init__(self, inner):
        self.inner = inner

    def plan(self, pm, start, goal, constraints=None, avoid_landmarks=(), blocked_segments=()):
        c = constraints or PlanConstraints(frozenset(avoid_landmarks), frozenset(blocked_segments))
        if "constraints" in inspect.signature(self.inner.plan).parameters:
            return self.inner.plan(pm, start, goal, c)
        return self.inner.plan(pm, start, goal, c.avoid_landmarks, c.blocked_segments)


def run_episode(ep, cfg, planner):
    """The evaluation's own episode runner, with ``planner`` put into the tree's context at
    the first tick (localization runs first, so no plan has been asked for yet). Until the
    runner builds the planner from ``planner.backend`` (the seams migration), this is how
    the ``vlm`` planner gets into an episode."""
    from pmnav_bt.experiments.evaluation import run_episode as run

    wrapped = _Planner(planner)

    def swap(tree) -> None:
        for b in tree.root.iterate():
            ctx = getattr(b, "ctx", None)
            if ctx is not None and ctx.planner is not wrapped:
                ctx.planner = wrapped
                return

    return run(ep, cfg, out_dir=None, on_tick=swap, plot=False).result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-n", type=int, default=1, help="episodes per tier per building")
    ap.add_argument("--tier", default="all")
    ap.add_argument("--building", default="all")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--wrong", type=float, default=0.3, help="the scripted server's wrong share")
    ap.add_argument("--tries", type=int, default=3, help="vlm.plan_tries")
    ap.add_argument("--endpoint", default=None, help="use this server instead")
    ap.add_argument("--out", type=Path, default=Path("out/vlm_sim_eval"))
    args = ap.parse_args()

    from pmnav_bt.experiments.options import building_names, tier_names
    from pmnav_bt.planning.graph_planner import GraphPlanner
    from pmnav_bt.sim.episodes import tier_definition

    cfg = load_config()
    buildings, tiers = building_names(args.building), tier_names(args.tier)
    eps, notes = episodes_for(buildings, tiers, args.n, args.seed)
    server = None
    if args.endpoint is None:
        responder = PlanningResponder(args.wrong, args.seed)
        server = ChatServer(responder).start()
    url = args.endpoint or server.base_url
    vlm = VlmPlanner(
        VlmClient(url, "scripted", timeout_s=30.0), tries=args.tries, max_gap=cfg.planner.max_gap
    )
    graph = GraphPlanner(max_gap=cfg.planner.max_gap)
    rows = []
    t0 = time.perf_counter()
    try:
        for ep in eps:
            row = {"episode": ep.id, "tier": ep.tier}
            for name, planner in (("graph", graph), ("vlm", vlm)):
                res = run_episode(ep, cfg, planner)
                row[name] = res.success
                row[f"{name}_failure"] = res.failure_reason
            rows.append(row)
            print(
                f"{ep.id:<28} graph {'ok' if row['graph'] else 'FAIL':<4} "
                f"vlm {'ok' if row['vlm'] else 'FAIL':<4} vlm plans so far "
                f"{vlm.stats.plans} (repaired {vlm.stats.repaired}, fallbacks "
                f"{vlm.stats.fallbacks})",
                flush=True,
            )
    finally:
        if server is not None:
            server.stop()
    wall = time.perf_counter() - t0
    tiers = [t for t in ("easy", "medium", "hard") if any(r["tier"] == t for r in rows)]
    lines = [
        "| planner | " + " | ".join(f"{t} SR (n)" for t in tiers) + " | all SR (n) |",
        "|---" * (len(tiers) + 2) + "|",
    ]
    for name in ("graph", "vlm"):
        cells = []
        for t in [*tiers, None]:
            sel = [r[name] for r in rows if t is None or r["tier"] == t]
            cells.append(f"{100.0 * sum(sel) / len(sel):.1f} ({len(sel)})")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    s = vlm.stats.to_dict()
    served = responder.counts if server is not None else {}
    summary = (
        f"vlm planner: {s['plans']} plans; valid on the first answer {s['valid_first']}, "
        f"repaired by re-prompts {s['repaired']}, graph fallbacks {s['fallbacks']}, "
        f"re-prompts {s['reprompts']}; issues {s['issues']}"
    )
    print(
        f"\n{len(rows)} episodes (n={args.n} per tier per building; seed {args.seed}); {wall:.0f} s"
    )
    for note in notes:
        print(f"note: {note}")
    print("\n".join(lines))
    print(summary)
    if served:
        print(f"scripted server answers: {served}")
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(
        json.dumps({"rows": rows, "vlm_stats": s, "server": served}, indent=1), encoding="utf-8"
    )
    (args.out / "results.md").write_text(
        f"# Graph vs VLM planner (scripted server, {args.wrong:.0%} wrong answers)\n\n"
        + "\n".join(lines)
        + f"\n\n{summary}\n\nscripted server answers: {served}\n\n"
        + tier_definition()
        + "\n",
        encoding="utf-8",
    )
    print(f"wrote {args.out / 'results.md'}")


if __name__ == "__main__":
    main()
