"""The ``--out`` folder of a run that writes results: whose results it holds, and where
a run that replaces them writes until it is done.

A run never destroys results it did not make. A folder that already holds results
(``results.jsonl``, ``results.json`` or ``results.md``) is refused, in one line, unless the
run goes on from them (``--resume``: the result store then refuses another config) or the
user asks to replace them (``--overwrite``). A replacing run writes into the subfolder
``overwriting/`` and moves its files over the earlier ones only when it has finished: an
interrupted ``--overwrite`` leaves the earlier results whole, its own finished episodes
in ``overwriting/``, and ``--resume`` goes on there. Finished results are never replaced
by partial ones.

``pmnav sim eval``, ``pmnav sim table3``, ``pmnav report`` and ``pmnav plan eval`` claim
their folder here before any work starts, and publish when their run is complete.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import typer

from pmnav_bt.errors import PmNavError

RESULT_FILES = ("results.jsonl", "results.json", "results.md")
STAGING = "overwriting"  # where an --overwrite run writes until it has finished

OVERWRITE_OPT = typer.Option(
    False,
    "--overwrite",
    help="Replace the results already in --out (kept whole until this run finishes; an "
    "interrupted run leaves them untouched).",
)


class ResultsFolderError(PmNavError):
    """``--out`` holds results this run would destroy."""


def held_results(folder: Path, files: tuple[str, ...] = RESULT_FILES) -> list[str]:
    """Which of ``files`` (paths relative to ``folder``) are there."""
    return [name for name in files if (folder / name).exists()]


def claim(out: Path, resume: bool, overwrite: bool, files: tuple[str, ...] = RESULT_FILES) -> Path:
    """The folder this run writes its results to: ``out`` itself, or ``out/overwriting``
    for a run that replaces results already there. ResultsFolderError when ``out`` holds
    results (any of ``files``; the first is the store ``--resume`` goes on from) and the
    run neither resumes nor overwrites them."""
    staged = out / STAGING
    store = files[0]
    if resume and overwrite:
        raise ResultsFolderError(
            "--resume and --overwrite: choose one (--resume also goes on with an "
            "interrupted --overwrite run)"
        )
    held = held_results(out, files)
    if resume:
        held_there = held_results(staged, files)
        if store in held_there:
            return staged
        for folder, names in ((out, held), (staged, held_there)):
            if names and store not in names:
                raise ResultsFolderError(
                    f"--resume: {folder} holds {', '.join(names)} but no {store} to go on "
                    "from; choose another --out, or replace them with --overwrite"
                )
        return out
    if overwrite and (held or staged.exists()):
        if staged.exists():
            shutil.rmtree(staged)  # an earlier --overwrite that never finished
        staged.mkdir()
        return staged
    if held:
        raise ResultsFolderError(
            f"--out {out} holds the results of an earlier run ({', '.join(held)}); go on "
            "with --resume (same config), replace them with --overwrite, or choose another "
            "--out"
        )
    if held_results(staged, files):
        raise ResultsFolderError(
            f"--out {out} holds an unfinished --overwrite run in {staged}; go on with "
            "--resume, start it again with --overwrite, or choose another --out"
        )
    return out


def publish(work: Path, out: Path) -> None:
    """A finished run's files take the place of the earlier ones (``work`` is ``out`` but
    for an ``--overwrite`` run, whose staging folder is then removed)."""
    if work == out:
        return
    for entry in sorted(work.iterdir(), key=lambda p: p.name in RESULT_FILES):
        target = out / entry.name
        if entry.is_dir() and target.is_dir():
            shutil.rmtree(target)
        os.replace(entry, target)
    work.rmdir()


def stopped_note(work: Path, out: Path) -> str:
    """What an interrupted run says of the earlier results (nothing if it had none)."""
    return "" if work == out else f"; the earlier results in {out} are untouched"
