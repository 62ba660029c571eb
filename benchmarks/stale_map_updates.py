"""Stale-map episodes: does the run write each disagreement on its route with the right kind?

Target (issue 38): on stale-map episodes, >= 95 % of the disagreements present on the
route are written to the map-updates file with the right kind (and SR >= 90).

Each generated episode runs with ``world.stale_map=1`` (one change on its route:
``sim/scene/stale_map.py``); the change the world made is drawn again from the same seed
(``stale_world``), and the episode's updates file is searched for an update of the
change's kind about its subject. A change is *present* when the body's true path (the
tree log's ``truth``) came within ``PASSED_M`` of it (a renamed room's door, a moved
landmark where the world has it, a closed segment's barrier: a run that fails before it
gets there had no chance to see it) and its plate shows it (a number-only plate layout of
realistic signage shows a renamed room's number alone). Episodes whose route offers no
change of the asked kinds are skipped and counted. Also printed: the updates that name no
change (false alarms), and the success rate. Episodes run one at a time, in this process.

    python benchmarks/stale_map_updates.py [--building fig2_hospital] [--tier hard] [-n 4]
        [--kinds renamed,moved,closed] [--set k=v ...] [--out out/stale_map]
"""

from __future__ import annotations

import argparse
import collections
import json
import math
from pathlib import Path

from pmnav_bt.config import load_config
from pmnav_bt.experiments.evaluation import run_episode
from pmnav_bt.map.updates import load_updates
from pmnav_bt.sim.episodes import episode_map, generate_episodes
from pmnav_bt.sim.scene import scene_rng
from pmnav_bt.sim.scene.plates import plate_lines
from pmnav_bt.sim.scene.signage import resolve_signage
from pmnav_bt.sim.scene.stale_map import stale_world

PASSED_M = 4.0  # a plate or barrier this near the body's path was in reading range


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--building", default="fig2_hospital")
    ap.add_argument("--tier", default="hard")
    ap.add_argument("-n", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kinds", default="renamed,moved,closed")
    ap.add_argument("--set", action="append", default=[], dest="overrides")
    ap.add_argument("--out", type=Path, default=Path("out/stale_map"))
    args = ap.parse_args()
    kinds = f"[{args.kinds}]"
    cfg = load_config(None, [*args.overrides, "world.stale_map=1", f"world.stale_kinds={kinds}"])
    per_kind = collections.Counter()
    hits = collections.Counter()
    passed = collections.Counter()
    passed_hits = collections.Counter()
    false_alarms, skipped, successes, runs = 0, 0, 0, 0
    for ep in generate_episodes(args.building, args.tier, args.n, seed=args.seed):
        _, pm = episode_map(ep)
        stale = stale_world(pm, cfg.world, ep.seed, ep.route, ep.goal)
        changes = stale.changes
        if not changes:
            skipped += 1
            continue
        run = run_episode(ep, cfg, out_dir=args.out / ep.id, plot=False)
        path = _true_path(run.tree_log)
        runs += 1
        successes += run.result.success
        written = load_updates(run.map_updates).updates
        found = set()
        for c in changes:
            per_kind[c.kind] += 1
            ok = any(u.kind == c.update_kind and u.subject == c.subject for u in written)
            hits[c.kind] += ok
            near = _near(path, _place(pm, stale.building, c)) and _shows(c, stale, cfg, ep)
            passed[c.kind] += near
            passed_hits[c.kind] += ok and near
            found |= {(c.update_kind, c.subject)}
        extra = [u for u in written if (u.kind, u.subject) not in found]
        false_alarms += len(extra)
        print(
            f"{ep.id}: {', '.join(f'{c.kind} {c.subject}' for c in changes)} -> "
            f"{'; '.join(f'{u.kind} {u.subject}' for u in written) or 'nothing written'}"
            f" [{'SUCCESS' if run.result.success else run.result.failure_reason}]",
            flush=True,
        )
    print(f"\n{args.building} {args.tier}, {runs} stale episodes ({skipped} without a change)")
    print("| change | n | written with the right kind | present | of those, written |")
    print("|---|---|---|---|---|")
    for k in [*sorted(per_kind), "all"]:
        n, h = _total(per_kind, k), _total(hits, k)
        p, ph = _total(passed, k), _total(passed_hits, k)
        if n:
            print(f"| {k} | {n} | {h} ({_pct(h, n)}) | {p} | {ph} ({_pct(ph, p)}) |")
    total = sum(per_kind.values())
    if total:
        print(f"\nupdates naming no change: {false_alarms}; SR {100.0 * successes / runs:.0f} %")


def _total(counter, key: str) -> int:
    return sum(counter.values()) if key == "all" else counter[key]


def _pct(a: int, b: int) -> str:
    return f"{100.0 * a / b:.0f} %" if b else "-"


def _true_path(tree_log: Path) -> list[tuple[float, float]]:
    out = []
    with open(tree_log, encoding="utf-8") as f:
        for line in f:
            truth = (json.loads(line).get("view") or {}).get("truth")
            if truth:
                out.append((truth[0], truth[1]))
    return out


def _place(pm, world_building, change) -> tuple[float, float]:
    if change.kind == "renamed":
        return world_building.room(change.subject).door
    if change.kind == "moved":
        return world_building.landmark(change.subject).pos
    seg = pm.segment(change.subject)
    a, b = pm.node_xy(seg.a), pm.node_xy(seg.b)
    return tuple((a + b) / 2.0)


def _shows(change, stale, cfg, ep) -> bool:
    """Whether the world's plate shows the change (a renamed room's, as the signage of the
    episode's world draws it); every other change shows."""
    if change.kind != "renamed":
        return True
    signage = resolve_signage(
        stale.building, cfg.world.signage, scene_rng(ep.seed, stale.building.name, "signage")
    )
    if signage is None:  # today's plates: the whole text
        return True
    style = signage.rooms[change.subject]
    return plate_lines(change.before, style) != plate_lines(change.after, style)


def _near(path, xy) -> bool:
    return any(math.dist(p, xy) <= PASSED_M for p in path)


if __name__ == "__main__":
    main()
