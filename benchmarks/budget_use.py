"""How much of the action budget episodes need: run the evaluation with a raised budget,
then see which wins would have fit the usual one.

    pmnav sim eval --building sign_sparse_2 --tier hard -n 16 --variants pmnav \\
        --set tree.budget_actions=1000 --set tree.budget_path_factor=6 --out out/big
    python benchmarks/budget_use.py out/big/results.jsonl --plot docs/img/budget_use.png

A raised budget changes nothing before the usual one runs out (the tree does not read its
budget), so an episode that wins in more actions than the usual budget is one the usual
evaluation loses to BUDGET_EXCEEDED, and the actions over say by how much. Prints, per
building: runs, wins, wins within the usual budget, and each win over it (episode:
actions over); with ``--plot``, actions used against corridor route length, with the
usual budget rule drawn.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from pmnav_bt.eval.task import action_budget


def load(paths: list[Path]) -> list[dict]:
    """The episode records of ``results.jsonl`` files (``pmnav sim eval``)."""
    rows = []
    for path in paths:
        with path.open() as f:
            rows += [json.loads(line) for line in f if line.strip()]
    return [r for r in rows if r.get("error") is None]


def usual_budget(row: dict) -> int:
    """The budget the usual evaluation gives this episode (the task's default rule)."""
    return action_budget(row["route_length"])


def summary(rows: list[dict]) -> list[str]:
    """One line per building: runs, wins, wins within the usual budget, wins over it."""
    by: dict[str, list[dict]] = defaultdict(list)
    for r in rows:
        by[r["building"]].append(r)
    lines = []
    for building, rs in sorted(by.items()):
        wins = [r for r in rs if r["success"]]
        over = [r for r in wins if r["steps"] > usual_budget(r)]
        text = ", ".join(f"{r['episode_id']}: +{r['steps'] - usual_budget(r)}" for r in over)
        lines.append(
            f"{building}: {len(rs)} runs, {len(wins)} wins, {len(wins) - len(over)} within "
            f"the usual budget" + (f"; over it: {text}" if over else "")
        )
    return lines


def plot(rows: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    route = np.array([r["route_length"] for r in rows])
    steps = np.array([r["steps"] for r in rows])
    won = np.array([r["success"] for r in rows])
    fits = steps <= np.array([usual_budget(r) for r in rows])
    xs = np.linspace(max(0.0, route.min() - 5), route.max() + 5, 200)
    ax.plot(xs, [action_budget(x) for x in xs], "k-", lw=1.5, label="usual budget")
    ax.scatter(
        route[won & fits],
        steps[won & fits],
        c="tab:green",
        s=22,
        label="won within the usual budget",
    )
    ax.scatter(
        route[won & ~fits],
        steps[won & ~fits],
        c="tab:red",
        s=30,
        marker="x",
        label="won past it (lost in the usual evaluation)",
    )
    if (~won).any():
        ax.scatter(route[~won], steps[~won], c="k", s=30, marker="v", label="lost anyway")
    ax.set_xlabel("corridor route length (m)")
    ax.set_ylabel("actions used")
    names = ", ".join(sorted({r["building"] for r in rows}))
    ax.set_title(f"{names}: actions used against the usual budget ({len(rows)} runs)")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+", type=Path, help="results.jsonl files")
    ap.add_argument("--plot", type=Path, help="write the plot here (PNG)")
    args = ap.parse_args(argv)
    missing = [str(p) for p in args.results if not p.is_file()]
    if missing:
        print(f"budget_use: no such file: {', '.join(missing)}", file=sys.stderr)
        return 2
    rows = load(args.results)
    if not rows:
        print("budget_use: no episode results in those files", file=sys.stderr)
        return 2
    print("\n".join(summary(rows)))
    if args.plot:
        plot(rows, args.plot)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
