"""Command-line values checked at the boundary: each bad value is one PmNavError line.

Numbers must be finite and in range, poses inside a plausible building, seeds
non-negative, job counts within the machine, episode counts bounded. The main entry
point turns typer/click usage errors into one line too (``run_cli``).
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable
from typing import Any

from pmnav_bt.errors import PmNavError

MAX_SEED = 2**63 - 1
MAX_EPISODES_PER_TIER = 10_000
MAX_POSE_COORD_M = 1000.0  # as a building's coordinates (docs/building-format.md)


class CliValueError(PmNavError):
    """A command-line value that is not usable."""


def _short(text: Any, n: int = 40) -> str:
    s = str(text)
    return s if len(s) <= n else s[: n - 3] + "..."


def finite(value: float, option: str, lo: float | None = None, hi: float | None = None) -> float:
    """``value`` if finite and within [lo, hi]; else a CliValueError naming ``option``."""
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CliValueError(f"{option} {_short(value)}: expected a finite number")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise CliValueError(f"{option} {_short(value)}: expected a number from {lo:g} to {hi:g}")
    return float(value)


def parse_number(text: str, option: str) -> float:
    """A finite float from text (no 400-digit overflows to inf, no nan)."""
    t = text.strip()
    if len(t) > 40:
        raise CliValueError(f"{option} {_short(t)}: number too long")
    try:
        v = float(t)
    except ValueError:
        raise CliValueError(f"{option} {_short(t)}: not a number") from None
    if not math.isfinite(v):
        raise CliValueError(f"{option} {_short(t)}: expected a finite number")
    return v


def parse_pose_text(text: str, option: str, need_yaw: bool = True) -> tuple[float, ...]:
    """'x,y,yaw_deg' (or 'x,y' when yaw is optional) as finite numbers in range."""
    parts = text.split(",")
    want = "x,y,yaw_deg" if need_yaw else "x,y[,yaw_deg]"
    if len(parts) not in ((3,) if need_yaw else (2, 3)):
        raise CliValueError(f"{option} {_short(text)!r}: expected {want}, e.g. 0,30,-90")
    vals = [parse_number(p, option) for p in parts]
    for v in vals[:2]:
        if abs(v) > MAX_POSE_COORD_M:
            raise CliValueError(
                f"{option} {_short(text)!r}: x and y must be within +-{MAX_POSE_COORD_M:g} m"
            )
    if len(vals) == 3 and abs(vals[2]) > 3600:
        raise CliValueError(f"{option} {_short(text)!r}: yaw must be within +-3600 degrees")
    return tuple(vals)


def seed(value: int, option: str = "--seed") -> int:
    if not 0 <= value <= MAX_SEED:
        raise CliValueError(f"{option} {_short(value)}: expected an integer from 0 to 2**63-1")
    return value


def cpu_count() -> int:
    """CPUs this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def jobs(value: int, option: str = "--jobs") -> int:
    """A job count from 1 to the CPUs this process may use."""
    most = cpu_count()
    if not 1 <= value <= most:
        raise CliValueError(f"{option} {_short(value)}: expected 1 to {most} (this machine's CPUs)")
    return value


def count(value: int, option: str, most: int = MAX_EPISODES_PER_TIER) -> int:
    if not 1 <= value <= most:
        raise CliValueError(f"{option} {_short(value)}: expected 1 to {most}")
    return value


def index(value: int, option: str = "--index") -> int:
    if not 0 <= value <= 10_000_000:
        raise CliValueError(f"{option} {_short(value)}: expected a non-negative index")
    return value


# -- the entry point ---------------------------------------------------------------------


def no_empty_values(args: list[str]) -> None:
    """No command takes an empty value: ``--out ''`` would silently be the current folder
    (a path of no characters is "."), ``--variants ''`` no variant at all, ``--building ''``
    no file. Refused before any command parses, whichever option or argument it is."""
    for i, arg in enumerate(args):
        if arg == "--":
            return
        if arg == "":
            before = args[i - 1] if i else ""
            if before.startswith("-"):
                raise CliValueError(
                    f"{_short(before)} '': an empty value; give one, or leave the option out"
                )
            raise CliValueError(f"argument {i + 1} is empty ''; give a value")
        if arg.startswith("--") and arg.endswith("=") and len(arg) > 3:
            raise CliValueError(f"{_short(arg)}: an empty value; give one, or leave it out")



def _click_exceptions():
    try:
        from typer._click import exceptions as ce  # typer >= 0.26 vendors click
    except ImportError:  # pragma: no cover - older typer
        from click import exceptions as ce
    return ce


def run_cli(app: Callable, argv: list[str] | None, prog: str, format_error: Callable) -> None:
    """Run a typer app; every error a user can cause becomes one line on stderr.

    ``format_error(err)`` gives the line for a PmNavError. Exit status: 2 for user
    errors and usage errors, the command's own status otherwise.
    """
    ce = _click_exceptions()
    try:
        no_empty_values(argv if argv is not None else sys.argv[1:])
    except CliValueError as err:
        _die(prog, str(err), 2)
    # typer >= 0.29 keeps Abort in typer.exceptions, not in its vendored click
    abort = getattr(ce, "Abort", None) or __import__("typer.exceptions").exceptions.Abort
    try:
        rv = app(args=argv, prog_name=prog, standalone_mode=False)
    except PmNavError as err:
        _die(prog, format_error(err), 2)
    except ce.ClickException as err:
        no_args = getattr(ce, "NoArgsIsHelpError", ())
        if no_args and isinstance(err, no_args):
            sys.exit(2)  # typer has printed the help
        where = f"{err.ctx.command_path}: " if getattr(err, "ctx", None) else ""
        _die(prog, where + err.format_message(), err.exit_code)
    except abort:
        _die(prog, "interrupted", 130)
    except OSError as err:  # a disk that filled up mid-write, a folder removed under us
        name = f"{_path_tail(str(err.filename), 80)}: " if err.filename else ""
        _die(prog, f"{name}{err.strerror or err}", 1)
    except MemoryError:
        _die(prog, "out of memory", 1)
    except RecursionError:
        _die(prog, "input nested too deeply", 1)
    sys.exit(rv if isinstance(rv, int) else 0)


def _path_tail(path: str, n: int) -> str:
    """``path`` in at most ``n`` characters, cut at the front: the file's name stays."""
    return path if len(path) <= n else "..." + path[-(n - 3) :]


def _die(prog: str, message: str, code: int) -> None:
    line = " ".join(str(message).split())  # one line, whatever the message held
    if len(line) > 1000:  # a message quoting a 100,000-character value
        line = line[:997] + "..."
    print(f"{prog}: error: {line}", file=sys.stderr)
    sys.exit(code)
