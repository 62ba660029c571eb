"""Node parameters: declared from a spec, unknown names rejected, and ``--help`` text.

rclpy silently ignores a ``-p name:=value`` whose name the node never declares, so a
typo (``-p bulding:=...``) would run with the default. ``check_unknown`` turns that
into an error naming the closest known parameter. ``usage`` prints the parameters of
a console script without starting ROS.
"""

from __future__ import annotations

import difflib
from typing import Any

from pmnav_bt.errors import PmNavError

# Parameters every rclpy node has.
BUILTIN = frozenset({"use_sim_time", "start_type_description_service"})


class UnknownParameterError(PmNavError):
    """A ``-p`` name that the node does not have."""


def check_unknown(node, spec: dict[str, tuple[Any, str]]) -> None:
    """UnknownParameterError if an override given to ``node`` (``--ros-args -p``, a
    params file) names no parameter of ``spec``."""
    given = getattr(node, "_parameter_overrides", {}) or {}
    known = set(spec) | BUILTIN
    for name in sorted(given):
        if name in known or name.startswith("qos_overrides."):
            continue
        close = difflib.get_close_matches(name, sorted(spec), n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise UnknownParameterError(
            f"unknown parameter {name!r} for node {node.get_name()!r}{hint} "
            f"(--help lists the parameters)"
        )


def wants_help(argv: list[str]) -> bool:
    """``-h``/``--help`` before any ``--ros-args``."""
    args = argv[1:]
    if "--ros-args" in args:
        args = args[: args.index("--ros-args")]
    return "-h" in args or "--help" in args


def usage(prog: str, summary: str, spec: dict[str, tuple[Any, str]], example: str) -> str:
    """Help text: what the node does, how to run it, its parameters with defaults."""
    width = max(len(k) for k in spec)
    lines = [f"usage: {prog} [--ros-args -p NAME:=VALUE ...]", "", summary, "", "parameters:"]
    for name, (default, desc) in spec.items():
        shown = repr(default) if isinstance(default, str) else str(default).lower()
        text = f"  {name:<{width}}  {shown}"
        lines.append(f"{text}  {desc}" if desc else text)
    lines += ["", f"example: {example}"]
    return "\n".join(lines)
