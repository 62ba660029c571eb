"""Ranges of pmnav-ros parameters: a bad ``-p name:=value`` is one line, before any work."""

from __future__ import annotations

import math
from typing import Any

from pmnav_bt.errors import PmNavError

# name -> (lowest, highest); 0 where the parameter says "0: the config's value".
LIMITS: dict[str, tuple[float, float]] = {
    "tick_hz": (0.0, 1000.0),
    "budget": (0, 100_000),
    "seed": (0, 2**63 - 1),
    "max_duration_s": (1.0, 7 * 86_400.0),
    "ready_timeout_s": (0.0, 86_400.0),
    "cmd_rate_hz": (1.0, 1000.0),
    "odom_timeout": (0.01, 60.0),
    "odom_fault_s": (0.01, 600.0),
    "camera_timeout": (0.01, 600.0),
    "sync_slop": (0.0, 10.0),
    "max_linear": (0.01, 5.0),
    "max_angular": (0.01, 10.0),
    "camera_height": (0.0, 10.0),
    "hfov_deg": (1.0, 179.0),
    "stall_s": (0.1, 600.0),
    "status_hz": (0.1, 100.0),
    "viz_hz": (0.1, 100.0),
    "view_port": (0, 65535),
}
MAX_TEXT = 4096


def check_parameters(params: dict[str, Any]) -> dict[str, Any]:
    """``params`` if every number is finite and in range and every text is short."""
    for name, v in params.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise PmNavError(f"parameter {name!r}: expected a finite number, got {v}")
        if isinstance(v, str) and (len(v) > MAX_TEXT or "\0" in v):
            raise PmNavError(f"parameter {name!r}: text too long or with a NUL character")
        if name in LIMITS and not isinstance(v, bool) and isinstance(v, (int, float)):
            lo, hi = LIMITS[name]
            if not lo <= v <= hi:
                raise PmNavError(f"parameter {name!r}: expected {lo:g} to {hi:g}, got {v:g}")
    if params.get("tick_hz", 0) and params["tick_hz"] < 0.5:
        raise PmNavError(
            f"parameter 'tick_hz': 0 (the config's) or 0.5 to 1000, got {params['tick_hz']:g}"
        )
    if params.get("tree_log"):
        from pmnav_bt.loading import check_output_file

        check_output_file(params["tree_log"], "parameter 'tree_log'")
    if params.get("map_updates_dir"):
        from pmnav_bt.loading import check_output_dir

        check_output_dir(params["map_updates_dir"], "parameter 'map_updates_dir'")
    return params
