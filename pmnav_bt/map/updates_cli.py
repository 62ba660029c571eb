"""``pmnav map updates FILE``: review what a run saw that disagrees with the map, and apply
the updates a person accepts to the building file.

It lists the updates (number, kind, where in the building's words, the evidence), then
applies the accepted ones (``--accept 1,3``, ``--accept all``, or one question each on a
terminal) through the building editor, shows the change as a unified diff, checks the
result loads, and writes it: to ``--out``, or over the building file after keeping the
old one as ``FILE.bak`` (a built-in building is never written over). The file is written
in the canonical layout, as ``pmnav annotate`` saves it (its comments stay in the backup),
so the diff shown is of the building's data. Never silent: with nothing accepted nothing
is written, and every write is named.
"""

from __future__ import annotations

import difflib
import sys
from pathlib import Path

import typer

from pmnav_bt.loading import atomic_write_text, check_output_file, read_text
from pmnav_bt.map import update_review as review
from pmnav_bt.map.updates import MapUpdate, load_updates

MAX_BACKUPS = 100  # FILE.bak, FILE.bak1, ... before asking the person to tidy up


def map_updates(
    file: Path = typer.Argument(..., help="A map-updates file (<episode>.map_updates.jsonl)."),
    building: str | None = typer.Option(
        None, "--building", help="The building file to apply to (default: the one the run had)."
    ),
    accept: str | None = typer.Option(
        None, "--accept", help="Apply these updates, numbered as listed: 1,3 or all."
    ),
    out: Path | None = typer.Option(
        None, "--out", help="Write the changed building here (default: over it, with a .bak)."
    ),
) -> None:
    """List the disagreements with the map a run wrote, and apply the accepted ones."""
    from pmnav_bt.map.building import dump_building
    from pmnav_bt.map.catalogue import (
        BUILTIN_DIR,
        is_generated_name,
        open_building,
        resolve_building_path,
    )
    from pmnav_bt.map.edit import BuildingEditor
    from pmnav_bt.map.priori_map import parse_building

    if out is not None:
        check_output_file(out, "--out", (".yaml", ".yml"))
    log = load_updates(file)
    name = building or log.building
    path = resolve_building_path(name)
    pm = parse_building(open_building(name))
    typer.echo(f"{file}: {len(log.updates)} disagreement(s) with {pm.building.name} ({path})")
    for i, u in enumerate(log.updates, 1):
        typer.echo(_row(i, u, pm))
    if not log.updates:
        return
    chosen = _choose(accept, log.updates)
    if not chosen:
        typer.echo("nothing accepted; the building is unchanged")
        return
    editor = BuildingEditor.open(path)
    for line in review.apply(editor, pm, [log.updates[i] for i in chosen]):
        typer.echo(f"applied: {line}")
    text = dump_building(editor.building())  # it must load (a BuildingFileError: one line)
    for p in editor.problems():
        typer.echo(p, err=True)
    if out is None and (path.resolve().parent == BUILTIN_DIR.resolve() or is_generated_name(name)):
        raise review.ReviewError(
            f"{name} is a built-in or generated building: give --out FILE for the changed copy"
        )
    old = read_text(path, "building")
    new_path = out if out is not None else path
    was = dump_building(pm.building)  # the diff of the data, not of the file's layout
    typer.echo("".join(difflib.unified_diff(
        was.splitlines(keepends=True), text.splitlines(keepends=True),
        fromfile=str(path), tofile=str(new_path),
    )), nl=False)  # fmt: skip
    if out is None:
        backup = _backup_name(path)
        atomic_write_text(backup, old)
        typer.echo(f"kept the old file as {backup}")
    atomic_write_text(new_path, text)
    typer.echo(f"wrote {new_path}: {len(chosen)} update(s) applied; check it with pmnav validate")


def _row(i: int, u: MapUpdate, pm) -> str:
    mark = "" if review.applies(u) else "  (listed only: cannot be applied)"
    return (
        f"{i:>3}  {u.kind:<16} {review.where(pm, u)}\n"
        f"     {'':<16} {review.evidence(u)}{mark}"
    )


def _choose(accept: str | None, updates) -> list[int]:
    if accept is not None:
        return review.parse_choice(accept, len(updates))
    if not sys.stdin.isatty():
        typer.echo("to apply: --accept 1,3 (numbers as listed) or --accept all")
        return []
    chosen = []
    for i, u in enumerate(updates):
        if review.applies(u) and typer.confirm(f"apply {i + 1} ({u.kind} {u.subject})?"):
            chosen.append(i)
    return chosen


def _backup_name(path: Path) -> Path:
    for k in range(MAX_BACKUPS):
        cand = path.with_name(path.name + (".bak" if k == 0 else f".bak{k}"))
        if not cand.exists():
            return cand
    raise review.ReviewError(f"{path}: {MAX_BACKUPS} backups already; remove old .bak files")
