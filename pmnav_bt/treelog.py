"""Reading a tree log (JSON lines: one ``tree`` record, then ``tick`` records) with checks.

Every record is type-checked so that rendering it cannot fail: node ids unique, every
parent defined before its children (no cycles), statuses from py_trees' four, maps where
maps belong. A last line cut short (the run was killed mid-write) is dropped with a
warning instead of losing the whole log. Pure Python: no py_trees import.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.loading import InputFileError, iter_text_lines, parse_json

STATUSES = frozenset({"SUCCESS", "FAILURE", "RUNNING", "INVALID"})
TICK_FIELDS = ("tick", "time", "status", "feedback", "blackboard")
NODE_FIELDS = ("id", "name", "class", "parent")
MAX_TREE_DEPTH = 100
MAX_NODES = 10_000


@dataclass
class TreeLog:
    """The checked content of a tree log; ``warning`` says what was dropped, if anything."""

    nodes: list[dict]
    ticks: list[dict]
    warning: str = ""
    lines: int = field(default=0)


def read_tree_log(path: str | Path) -> TreeLog:
    """Read and check a tree log; PmNavError names the file, the line and what is wrong."""
    path = Path(path)
    nodes: list[dict] | None = None
    ticks: list[dict] = []
    warning = ""
    pending: tuple[int, str] | None = None  # a line without its newline: maybe cut short
    count = 0
    try:
        for i, line, complete in iter_text_lines(path, "tree log"):
            count = i
            if not line.strip():
                continue
            if not complete:
                pending = (i, line)
                break
            rec = _record(path, i, line)
            nodes = _take(path, i, rec, nodes, ticks)
    except InputFileError as err:
        raise PmNavError(str(err)) from None
    if pending is not None:
        i, line = pending
        try:
            rec = _record(path, i, line)
        except PmNavError:
            warning = (
                f"{path}: line {i}: the last line was cut short (the run stopped mid-write); "
                f"replaying the {len(ticks)} complete tick records before it"
            )
        else:
            nodes = _take(path, i, rec, nodes, ticks)
    if nodes is None:
        raise PmNavError(f"{path}: not a tree log (no tree record); write one with --tree-log")
    return TreeLog(nodes, ticks, warning, count)


def _record(path: Path, i: int, line: str) -> dict:
    try:
        rec = parse_json(line, path, f"line {i}", allow_nan=True)
    except InputFileError as err:
        raise PmNavError(str(err)) from None
    if not isinstance(rec, dict):
        raise PmNavError(f"{path}: line {i}: not a tree log record (not a JSON object)")
    return rec


def _take(path: Path, i: int, rec: dict, nodes: list[dict] | None, ticks: list[dict]):
    kind = rec.get("type")
    if kind == "tree":
        if nodes is not None:
            raise PmNavError(f"{path}: line {i}: a second tree record (one log, one tree)")
        return _check_nodes(path, i, rec.get("nodes"))
    if kind == "tick":
        if nodes is None:
            raise PmNavError(
                f"{path}: line {i}: not a tree log (a tick record before the tree record)"
            )
        ticks.append(_check_tick(path, i, rec))
    elif not isinstance(kind, str):
        raise PmNavError(f"{path}: line {i}: record 'type' must be a string, got {_brief(kind)}")
    return nodes


def _check_nodes(path: Path, i: int, nodes: Any) -> list[dict]:
    where = f"{path}: line {i}: tree record"
    if not isinstance(nodes, list) or not nodes:
        raise PmNavError(f"{where}: 'nodes' must be a non-empty list, got {_brief(nodes)}")
    if len(nodes) > MAX_NODES:
        raise PmNavError(f"{where}: {len(nodes)} nodes; at most {MAX_NODES}")
    depth: dict[str, int] = {}
    for k, n in enumerate(nodes):
        at = f"{where}: nodes[{k}]"
        if not isinstance(n, dict):
            raise PmNavError(f"{at}: expected an object, got {_brief(n)}")
        missing = [f for f in NODE_FIELDS if f not in n]
        if missing:
            raise PmNavError(f"{at}: lacks {', '.join(missing)}")
        for f in ("id", "name", "class"):
            if not isinstance(n[f], str):
                raise PmNavError(f"{at}.{f}: expected a string, got {_brief(n[f])}")
        if n["id"] in depth:
            raise PmNavError(f"{at}.id: duplicate node id {_brief(n['id'])}")
        parent = n["parent"]
        if parent is None:
            depth[n["id"]] = 0
            continue
        if not isinstance(parent, str):
            raise PmNavError(f"{at}.parent: expected a string or null, got {_brief(parent)}")
        if parent not in depth:
            raise PmNavError(f"{at}.parent: {_brief(parent)} is not an earlier node's id")
        depth[n["id"]] = depth[parent] + 1
        if depth[n["id"]] > MAX_TREE_DEPTH:
            raise PmNavError(f"{at}: the tree is deeper than {MAX_TREE_DEPTH} levels")
    return nodes


def _check_tick(path: Path, i: int, rec: dict) -> dict:
    where = f"{path}: line {i}: tick record"
    missing = sorted(f for f in TICK_FIELDS if f not in rec)
    if missing:
        raise PmNavError(f"{path}: line {i}: a tick record lacks {', '.join(missing)}")
    tick, t = rec["tick"], rec["time"]
    if not isinstance(tick, int) or isinstance(tick, bool):
        raise PmNavError(f"{where}: 'tick' must be an integer, got {_brief(tick)}")
    if t is not None and (
        not isinstance(t, (int, float)) or isinstance(t, bool) or not math.isfinite(t)
    ):
        raise PmNavError(f"{where}: 'time' must be a finite number or null, got {_brief(t)}")
    for f in ("status", "feedback", "blackboard"):
        if not isinstance(rec[f], dict):
            raise PmNavError(f"{where}: '{f}' must be an object, got {_brief(rec[f])}")
    for k, v in rec["status"].items():
        if v not in STATUSES:
            raise PmNavError(
                f"{where}: status of {_brief(k)} must be one of {', '.join(sorted(STATUSES))}, "
                f"got {_brief(v)}"
            )
    for k, v in rec["feedback"].items():
        if not isinstance(v, str):
            raise PmNavError(f"{where}: feedback of {_brief(k)} must be a string, got {_brief(v)}")
    return rec


def _brief(v: Any, n: int = 40) -> str:
    s = repr(v)
    return s if len(s) <= n else s[: n - 3] + "..."
