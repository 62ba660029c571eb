"""``pmnav tree``: draw the behaviour tree, and step through a snapshot log.

Mounted by ``pmnav_bt/experiments/cli.py`` (``app.add_typer(tree_cli.app, name="tree")``).
This module imports only typer at import time (``pmnav --help`` pulls in neither py_trees
nor pybullet);
each command imports what it needs. User errors raise PmNavError, which ``pmnav``'s main
prints in one line.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import typer

from pmnav_bt.errors import PmNavError

app = typer.Typer(
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="The behaviour tree: draw it (dot/SVG/PNG), or replay a tree log tick by tick.",
)

RENDER_BUILDING = "fig2_hospital"


def _formats(text: str) -> list[str]:
    from pmnav_bt.trees.render import FORMATS

    out = [f.strip().lower() for f in text.split(",") if f.strip()]
    bad = [f for f in out if f not in FORMATS]
    if bad or not out:
        raise PmNavError(f"--format {text!r}: choose from {', '.join(FORMATS)} (comma-separated)")
    return out


def _build_tree(variant: str):
    """The real tree for ``variant`` on the built-in fig2_hospital, on a test-double body
    (drawing a tree ticks nothing: no simulator needed).

    Returns (tree, close) where close() releases the worker."""
    import py_trees

    from pmnav_bt.config import load_config
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.testing.doubles import FakeBase
    from pmnav_bt.trees.runner import build_tree, make_context

    building = load_building(RENDER_BUILDING)
    config = load_config(overrides=[f"tree.variant={variant}"])
    ctx = make_context(FakeBase(), parse_building(building), config)

    def close() -> None:
        ctx.worker.shutdown()

    try:
        py_trees.blackboard.Blackboard.clear()
        tree = build_tree(ctx, building.rooms[0].id)
    except BaseException:
        close()
        raise
    return tree, close


@app.command()
def render(
    variant: str = typer.Option(
        "pmnav", "--variant", help="A tree variant (registered in pmnav_bt/tree_variants.py)."
    ),
    out: Path = typer.Option(Path("."), "--out", help="Folder for the pictures."),
    name: str | None = typer.Option(None, "--name", help="File name stem [default: the variant]."),
    formats: str = typer.Option(
        "dot,svg,png", "--format", help="Comma-separated: dot, svg, png (svg/png need Graphviz)."
    ),
    rankdir: str = typer.Option("TB", "--rankdir", help="TB (top-down) or LR (left-right)."),
    collapse: bool = typer.Option(
        False, "--collapse-decorators", help="Fold each decorator into the node it decorates."
    ),
    log: Path | None = typer.Option(
        None, "--log", help="Draw the tree of this tree log instead of building one."
    ),
    tick: int | None = typer.Option(
        None, "--tick", help="With --log: colour the nodes by their status at this tick."
    ),
) -> None:
    """Draw the PM-Nav tree as .dot, .svg and .png (the real tree, or one from a tree log)."""
    from pmnav_bt.loading import check_output_dir, safe_filename
    from pmnav_bt.trees.render import render_log_tick, render_tree

    fmts = _formats(formats)
    check_output_dir(out)
    if name is not None:
        name = safe_filename(name)
    rankdir = rankdir.upper()
    if rankdir not in ("TB", "LR", "BT", "RL"):
        raise PmNavError(f"--rankdir {rankdir!r}: choose TB or LR")
    if tick is not None and log is None:
        raise PmNavError("--tick needs --log: statuses come from a tree log")
    if log is not None:
        replay = load_replay(log)
        record = find_tick(replay, log, tick) if tick is not None else None
        title = log.name
        if record is not None:
            title += f": tick {record['tick']}"
            title += f", t={record['time']} s" if record["time"] is not None else ""
        written = render_log_tick(
            replay.nodes,
            out,
            name or safe_filename(log.stem) + (f"_tick{tick}" if tick is not None else ""),
            record,
            formats=fmts,
            rankdir=rankdir,
            collapse_decorators=collapse,
            title=title,
        )
    else:
        from pmnav_bt.tree_variants import TREE_VARIANTS

        if variant not in TREE_VARIANTS.names():
            choices = ", ".join(TREE_VARIANTS.names())
            raise PmNavError(f"--variant {variant!r}: choose from {choices}")
        tree, close = _build_tree(variant)
        try:
            written = render_tree(
                tree.root,
                out,
                name or variant,
                formats=fmts,
                rankdir=rankdir,
                collapse_decorators=collapse,
                title=f"PM-Nav behaviour tree, variant {variant}",
            )
        finally:
            close()
    for path in written.values():
        typer.echo(f"wrote {path}")


# -- replay ------------------------------------------------------------------------------


def load_replay(path: Path):
    """A tree log read back and checked (PmNavError names the file and what is wrong)."""
    from pmnav_bt.trees.snapshots import Replay

    rp = Replay.load(path)
    if rp.warning:
        typer.echo(f"pmnav: warning: {rp.warning}", err=True)
    return rp


def _span(replay) -> str:
    if not replay.ticks:
        return "no ticks"
    return f"ticks {replay.ticks[0]['tick']}..{replay.ticks[-1]['tick']}"


def find_tick(replay, path: Path, n: int) -> dict:
    """The record of tick ``n``, or PmNavError saying which ticks the log holds."""
    for t in replay.ticks:
        if t["tick"] == n:
            return t
    raise PmNavError(f"{path}: no tick {n} in this log (it holds {_span(replay)})")


def _changed(prev: dict | None, cur: dict) -> bool:
    return prev is None or prev["status"] != cur["status"]


@app.command()
def replay(
    log: Path = typer.Argument(..., help="A tree log (JSON lines) written by a run."),
    tick: int | None = typer.Option(None, "--tick", help="Print only this tick."),
    start: int | None = typer.Option(None, "--from", help="First tick to print."),
    stop: int | None = typer.Option(None, "--to", help="Last tick to print."),
    visited_only: bool = typer.Option(
        False, "--visited-only", help="Show only the nodes ticked in each tick."
    ),
    changes: bool = typer.Option(
        False, "--changes", help="Print only ticks where a status changed from the tick before."
    ),
    step: bool = typer.Option(
        False, "--step", help="Wait for Enter between ticks (q then Enter quits); needs a terminal."
    ),
) -> None:
    """Print a tree log tick by tick: each node's status (✔ ✘ * -, · not ticked) and feedback."""
    rp = load_replay(log)
    if tick is not None:
        if start is not None or stop is not None:
            raise PmNavError("--tick and --from/--to: give one or the other")
        records = [find_tick(rp, log, tick)]
    else:
        if start is not None and stop is not None and start > stop:
            raise PmNavError(f"--from {start} is after --to {stop}")
        records, prev = [], None
        for t in rp.ticks:
            keep = (start is None or t["tick"] >= start) and (stop is None or t["tick"] <= stop)
            if keep and (not changes or _changed(prev, t)):
                records.append(t)
            prev = t
        if not records:
            if start is not None and stop is not None:
                where = f"in ticks {start}..{stop}"
            elif start is not None:
                where = f"at or after tick {start}"
            else:
                where = f"at or before tick {stop}" if stop is not None else "at all"
            what = "tick with a status change" if changes else "tick"
            raise PmNavError(f"{log}: no {what} {where} (the log holds {_span(rp)})")
    print_ticks(
        rp, records, visited_only, wait=_wait_for_enter if step and sys.stdin.isatty() else None
    )


def _wait_for_enter() -> bool:
    """Prompt on stderr and read a line; False (stop) on q, end of input or Ctrl-C."""
    typer.echo("-- Enter: next tick, q: quit --", err=True, nl=False)
    try:
        answer = sys.stdin.readline()
    except KeyboardInterrupt:
        return False
    return bool(answer) and not answer.strip().lower().startswith("q")


def print_ticks(
    rp,
    records: list[dict],
    visited_only: bool = False,
    wait: Callable[[], bool] | None = None,
    console=None,
) -> int:
    """Print ``records`` of a Replay, coloured on a terminal; between two ticks call
    ``wait()`` (stop when it returns False) or print a blank line. Returns how many were
    printed."""
    from rich.console import Console

    from pmnav_bt.trees.live import styled

    console = console or Console()
    shown = 0
    for i, t in enumerate(records):
        text = rp.render(t, visited_only)
        if console.is_terminal:
            console.print(styled(text), soft_wrap=True)
        else:
            console.print(text, markup=False, highlight=False, soft_wrap=True)
        shown += 1
        if i == len(records) - 1:
            break
        if wait is not None:
            if not wait():
                break
        else:
            console.print()
    return shown
