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

# The log's format. 1: no version field (statuses, feedback, blackboard); 2: the tree
# record names its version and the run (building, goal); tick records may hold a
# ``view`` entry (trees/view_record.py) for the web view. A reader takes every version up
# to its own and refuses a newer one in one line.
SCHEMA_VERSION = 2
STATUSES = frozenset({"SUCCESS", "FAILURE", "RUNNING", "INVALID"})
TICK_FIELDS = ("tick", "time", "status", "feedback", "blackboard")
NODE_FIELDS = ("id", "name", "class", "parent")
MAX_TREE_DEPTH = 100
MAX_NODES = 10_000


@dataclass
class TreeLog:
    """The checked content of a tree log; ``warning`` says what was dropped, if anything;
    ``header`` is the tree record (its ``version``, and from version 2 its ``run``)."""

    nodes: list[dict]
    ticks: list[dict]
    warning: str = ""
    lines: int = field(default=0)
    header: dict = field(default_factory=dict)


def read_tree_log(path: str | Path) -> TreeLog:
    """Read and check a tree log; PmNavError names the file, the line and what is wrong."""
    path = Path(path)
    lines = TreeLogLines(str(path))
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
            lines.add(i, line)
    except InputFileError as err:
        raise PmNavError(str(err)) from None
    if pending is not None:
        i, line = pending
        try:
            rec = lines.parse(i, line)
        except PmNavError:
            warning = (
                f"{path}: line {i}: the last line was cut short (the run stopped mid-write); "
                f"replaying the {len(lines.ticks)} complete tick records before it"
            )
        else:
            lines.take(i, rec)
    if lines.nodes is None:
        raise PmNavError(f"{path}: not a tree log (no tree record); write one with --tree-log")
    return TreeLog(lines.nodes, lines.ticks, warning, count, lines.header)


class TreeLogLines:
    """Checks a tree log line by line: a file read whole, or one followed as it is written.

    ``source`` names it in errors. ``new_runs``: a second tree record starts a new run
    (a node that appends every goal's tree to one log) instead of being an error; the
    ticks held are then dropped."""

    def __init__(self, source: str, new_runs: bool = False) -> None:
        self.source = source
        self.new_runs = new_runs
        self.header: dict = {}
        self.nodes: list[dict] | None = None
        self.ticks: list[dict] = []

    def parse(self, i: int, line: str) -> dict:
        """Line ``i`` as a JSON object (PmNavError: not one)."""
        try:
            rec = parse_json(line, self.source, f"line {i}", allow_nan=True)
        except InputFileError as err:
            raise PmNavError(str(err)) from None
        if not isinstance(rec, dict):
            raise PmNavError(f"{self.source}: line {i}: not a tree log record (not a JSON object)")
        return rec

    def add(self, i: int, line: str) -> dict:
        """Parse, check and keep line ``i``; returns its record."""
        return self.take(i, self.parse(i, line))

    def take(self, i: int, rec: dict) -> dict:
        """Check and keep a record of line ``i``; returns it."""
        where = f"{self.source}: line {i}"
        kind = rec.get("type")
        if kind == "tree":
            if self.nodes is not None and not self.new_runs:
                raise PmNavError(f"{where}: a second tree record (one log, one tree)")
            header = check_header(rec, f"{where}: tree record")
            self.nodes = _check_nodes(self.source, i, rec.get("nodes"))
            self.header, self.ticks = header, []
        elif kind == "tick":
            if self.nodes is None:
                raise PmNavError(f"{where}: not a tree log (a tick record before the tree record)")
            self.ticks.append(check_tick(rec, where))
        elif not isinstance(kind, str):
            raise PmNavError(f"{where}: record 'type' must be a string, got {_brief(kind)}")
        return rec


def _check_nodes(path: Path | str, i: int, nodes: Any) -> list[dict]:
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


def check_header(rec: dict, where: str) -> dict:
    """A tree record's version (1 when it has none: logs written before versions) and
    ``run`` (building, goal), checked; a newer version than this reader's is refused."""
    version = rec.get("version", 1)
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise PmNavError(f"{where}: 'version' must be a positive integer, got {_brief(version)}")
    if version > SCHEMA_VERSION:
        raise PmNavError(
            f"{where}: schema version {version} is newer than this pmnav reads "
            f"(up to {SCHEMA_VERSION}); update pmnav"
        )
    run = rec.get("run", {})
    if not isinstance(run, dict):
        raise PmNavError(f"{where}: 'run' must be an object, got {_brief(run)}")
    for f in ("building", "goal"):
        if run.get(f) is not None and not isinstance(run[f], str):
            raise PmNavError(f"{where}: run.{f} must be a string, got {_brief(run[f])}")
    return {"version": version, "run": run}


def check_tick(rec: dict, where_line: str) -> dict:
    """A tick record, checked (``where_line``: the file and line, for the error)."""
    where = f"{where_line}: tick record"
    missing = sorted(f for f in TICK_FIELDS if f not in rec)
    if missing:
        raise PmNavError(f"{where_line}: a tick record lacks {', '.join(missing)}")
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
    if "view" in rec:
        _check_view(rec["view"], f"{where}: view")
    return rec


# -- the view entry (version 2): the shape of each key the web view draws -------------------


def _num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _nums(v: Any, n: int | None) -> bool:
    return isinstance(v, list) and (n is None or len(v) == n) and all(_num(x) for x in v)


def _points(v: Any) -> bool:
    return isinstance(v, list) and all(_nums(p, 2) for p in v)


def _strs(v: Any) -> bool:
    return isinstance(v, list) and all(isinstance(x, str) for x in v)


def _failure(v: Any) -> bool:
    return (
        isinstance(v, dict)
        and isinstance(v.get("code"), str)
        and isinstance(v.get("message"), str)
        and (v.get("root") is None or _failure(v["root"]))
    )


def _plan(v: Any) -> bool:
    steps = v.get("steps") if isinstance(v, dict) else None
    return (
        isinstance(v, dict)
        and isinstance(v.get("text"), str)
        and _points(v.get("path"))
        and isinstance(steps, list)
        and all(
            isinstance(s, dict)
            and all(isinstance(s.get(f), str) for f in ("landmark", "action", "text"))
            and _nums(s.get("xy"), 2)
            for s in steps
        )
    )


def _belief(v: Any) -> bool:
    return (
        isinstance(v, dict)
        and _points(v.get("xy"))
        and _nums(v.get("w"), len(v.get("xy") or []))
        and _num(v.get("best"))
    )


def _found(v: Any) -> bool:
    return (
        isinstance(v, dict)
        and isinstance(v.get("label"), str)
        and _nums(v.get("box"), 4)
        and _num(v.get("score"))
        and (v.get("entity") is None or isinstance(v["entity"], str))
    )


def _frame(v: Any) -> bool:
    return (
        isinstance(v, dict)
        and isinstance(v.get("jpeg"), str)
        and _nums(v.get("size"), 2)
        and _strs(v.get("what"))
        and isinstance(v.get("found"), list)
        and all(_found(d) for d in v["found"])
    )


# key -> (the check of a non-null value, what it should be)
VIEW_CHECKS = {
    "pose": (lambda v: _nums(v, 3), "[x, y, yaw]"),
    "odom": (lambda v: _nums(v, 3), "[x, y, yaw]"),
    "truth": (lambda v: _nums(v, 3), "[x, y, yaw]"),
    "sigma": (lambda v: _num(v) and v >= 0, "a number of metres, at least 0"),
    "plan": (_plan, "a plan: text, path [[x, y], ...], steps"),
    "belief": (_belief, "a belief: xy [[x, y], ...], w (one weight each), best"),
    "failure": (_failure, "a failure: code, message, optional root"),
    "recovering": (_failure, "a failure: code, message, optional root"),
    "frame": (_frame, "a frame: jpeg, size [w, h], what, found"),
    "seen": (_strs, "a list of names"),
}


def _check_view(view: Any, where: str) -> None:
    """Each key the web view draws has the shape it expects (unknown keys are left)."""
    if not isinstance(view, dict):
        raise PmNavError(f"{where}: must be an object, got {_brief(view)}")
    for key, (ok, what) in VIEW_CHECKS.items():
        if key in view and view[key] is not None and not ok(view[key]):
            raise PmNavError(f"{where}.{key}: expected {what}, got {_brief(view[key])}")


def _brief(v: Any, n: int = 40) -> str:
    s = repr(v)
    return s if len(s) <= n else s[: n - 3] + "..."
