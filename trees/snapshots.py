"""Tree status for debugging: per-tick JSON snapshots, replay, and unicode rendering.

A log is JSON lines: first the tree's structure (with the schema ``version`` and, from
version 2, the ``run``: building and goal), then one record per tick with every visited
node's status and feedback message, the blackboard keys written in that tick and, from
version 2, the ``view`` entry (``trees/view_record.py``: pose, plan, belief, failure,
camera frame). ``pmnav tree replay LOG`` steps through it; ``pmnav view LOG`` shows it
in a browser.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import py_trees

from pmnav_bt.treelog import SCHEMA_VERSION

STATUS_MARK = {"SUCCESS": "✔", "FAILURE": "✘", "RUNNING": "*", "INVALID": "-"}


def brief(value: Any, limit: int = 160) -> Any:
    """A short JSON-safe rendering of a blackboard value."""
    if value is None or isinstance(value, (bool, int, str)):
        return value if not isinstance(value, str) else value[:limit]
    if isinstance(value, float):
        return round(value, 4) if math.isfinite(value) else str(value)
    if (
        isinstance(value, (tuple, list))
        and len(value) <= 4
        and all(isinstance(v, (int, float)) for v in value)
    ):
        return [brief(v) for v in value]
    if isinstance(value, np.ndarray):
        return f"array{tuple(value.shape)}"
    if hasattr(value, "text") and callable(value.text):  # Plan, PlanStep
        return value.text().splitlines()[0][:limit]
    if isinstance(value, (list, tuple, set, frozenset)):
        return f"{type(value).__name__}[{len(value)}]"
    return str(value)[:limit]


def structure(root: py_trees.behaviour.Behaviour) -> list[dict]:
    """Nodes in depth-first pre-order, each with its parent's id."""
    out: list[dict] = []

    def walk(node, parent) -> None:
        out.append(
            {
                "id": str(node.id),
                "name": node.name,
                "class": type(node).__name__,
                "parent": str(parent.id) if parent is not None else None,
            }
        )
        for c in node.children:
            walk(c, node)

    walk(root, None)
    return out


class SnapshotLogger:
    """Writes one JSON record per tick (a post-tick handler of a BehaviourTree).

    ``view``: a ``trees.view_record.ViewRecorder`` adds each tick's ``view`` entry and
    the tree record's ``run``; ``goal``: the goal named there."""

    def __init__(
        self,
        tree: py_trees.trees.BehaviourTree,
        out: TextIO,
        clock_now=None,
        view=None,
        goal: str | None = None,
    ):
        self.out = out
        self.now = clock_now
        self.view = view
        self.visitor = py_trees.visitors.SnapshotVisitor()
        tree.visitors.append(self.visitor)
        py_trees.blackboard.Blackboard.enable_activity_stream(maximum_size=10000)
        rec: dict[str, Any] = {"type": "tree", "version": SCHEMA_VERSION}
        if view is not None:
            rec["run"] = view.run_fields(goal)
        rec["nodes"] = structure(tree.root)
        self._write(rec)

    def _write(self, rec: dict) -> None:
        self.out.write(json.dumps(rec) + "\n")

    def __call__(self, tree: py_trees.trees.BehaviourTree) -> None:
        stream = py_trees.blackboard.Blackboard.activity_stream
        raw = {}
        if stream is not None:
            for item in stream.data:
                if item.activity_type in ("WRITE", "INITIALISED"):
                    raw[item.key] = item.current_value
            stream.clear()
        statuses, feedback = {}, {}
        for node in tree.root.iterate():
            if node.id in self.visitor.visited:
                statuses[str(node.id)] = node.status.name
                if node.feedback_message:
                    feedback[str(node.id)] = node.feedback_message
        rec = {
            "type": "tick",
            "tick": tree.count,
            "time": round(self.now(), 3) if self.now else None,
            "status": statuses,
            "feedback": feedback,
            "blackboard": {k: brief(v) for k, v in raw.items()},
        }
        if self.view is not None:
            rec["view"] = self.view(raw)
        self._write(rec)


@dataclass
class Replay:
    """A snapshot log read back: the tree's nodes and its tick records."""

    nodes: list[dict]
    ticks: list[dict]

    warning: str = ""  # set when the last line was cut short and dropped

    @classmethod
    def load(cls, path: str | Path) -> Replay:
        """Read and check a log; PmNavError names the file and what is wrong."""
        from pmnav_bt.treelog import read_tree_log

        log = read_tree_log(path)
        return cls(log.nodes, log.ticks, log.warning)

    def render(self, tick: dict, visited_only: bool = False) -> str:
        """The tree at one tick, as unicode, with statuses and feedback."""
        children: dict[str | None, list[dict]] = {}
        for n in self.nodes:
            children.setdefault(n["parent"], []).append(n)
        t = tick["time"]
        lines = [f"tick {tick['tick']}  t={t} s" if t is not None else f"tick {tick['tick']}"]

        def walk(n: dict, depth: int) -> None:
            st = tick["status"].get(n["id"])
            if visited_only and st is None:
                return
            mark = STATUS_MARK.get(st, " ") if st else "·"
            fb = tick["feedback"].get(n["id"])
            lines.append(
                f"{'    ' * depth}{mark} {n['name']} [{n['class']}]" + (f" -- {fb}" if fb else "")
            )
            for c in children.get(n["id"], []):
                walk(c, depth + 1)

        for root in children.get(None, []):
            walk(root, 0)
        if tick["blackboard"]:
            lines.append("blackboard:")
            lines += [f"  {k} = {v}" for k, v in sorted(tick["blackboard"].items())]
        return "\n".join(lines)

    def iter_render(self, visited_only: bool = False) -> Iterator[str]:
        for t in self.ticks:
            yield self.render(t, visited_only)
