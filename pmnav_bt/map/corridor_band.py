"""A corridor's width in a floor-plan grid: the band its centre line keeps free all along.

A building file models a corridor as one rectangle about its centre line, so its width
is what is free along the whole line, not a median: a line through a gap between one
room's corner and another's (walls on both sides, but never abreast) has the median
wall-to-wall width of the hall, and the gap's is what the robot gets. Across the line,
rays look out to ``REACH_M`` on each side for a wall every ``STEP_M`` along it; each
side's clearance is the widest that every stretch of ``NARROW_RUN_M`` keeps (a narrowing
shorter than that, a grid speck or a door jamb, is not the corridor's).

``pmnav map import-rmf`` sizes and centres its corridors by this measure and ``pmnav
validate`` checks a grid building's widths by it, so an import does not warn on its own
corridors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.map.floorplan import FloorPlanImage

REACH_M = 5.0  # rays look this far for a wall on each side
STEP_M = 0.25  # about this many metres of the whole line per ray (denser when trimmed)
NARROW_RUN_M = 0.5  # a narrowing at least this long sets a corridor's width
END_M = 0.5  # left out at each end of the line
MIN_LENGTH_M = 0.1  # a shorter line has no band
WALLED = 0.5  # the line is between walls where this share of its rays hit on both sides


@dataclass(frozen=True)
class Band:
    """The free band about a line: each side's clearance kept all along (m; inf where a
    side has no wall within ``REACH_M``), and whether walls stand on both sides."""

    left: float
    right: float
    walled: bool

    @property
    def width(self) -> float:
        """Between walls, the band's breadth; with one side open (a hall), twice the walled
        side's clearance; inf with no wall on either side."""
        if self.walled:
            return self.left + self.right
        return 2.0 * min(self.left, self.right)

    @property
    def about_line(self) -> float:
        """The widest rectangle about the line itself that is free all along: twice the
        nearer side's clearance (the band's breadth once the line is in its middle; a
        spur drawn along one wall keeps its width, whatever is across from it)."""
        return 2.0 * min(self.left, self.right)

    @property
    def offset(self) -> float:
        """How far left of the line the band's middle is (0 unless walled)."""
        return (self.left - self.right) / 2.0 if self.walled else 0.0


def free_band(plan: FloorPlanImage, walls: np.ndarray, a, b) -> Band | None:
    """The free band about the line a-b in ``walls`` (the plan's free cells, small clutter
    filled in: widths are wall to wall); None for a line under ``MIN_LENGTH_M``. Left is
    counter-clockwise from a->b. The ends (``END_M``, at most a quarter of the line each)
    are left out: there the line meets a junction's wall or an end wall across it."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    length = float(np.linalg.norm(b - a))
    if length < MIN_LENGTH_M:
        return None
    u = (b - a) / length
    n = np.array([-u[1], u[0]])
    trim = min(END_M, length / 4.0)
    s = np.linspace(trim, length - trim, max(3, int(length / STEP_M)))
    t = np.arange(plan.resolution / 2.0, REACH_M, plan.resolution / 2.0)
    clear = []
    for side in (1.0, -1.0):
        pts = a + s[:, None, None] * u + side * t[None, :, None] * n
        ok = plan.mask_at(walls, pts.reshape(-1, 2)).reshape(len(s), len(t))
        hit = ~ok.all(axis=1)
        first = np.where(hit, np.argmin(ok, axis=1), len(t) - 1)
        clear.append(np.where(hit, t[first], np.inf))
    left, right = clear
    walled = bool((np.isfinite(left) & np.isfinite(right)).mean() >= WALLED)
    return Band(_narrowest(left, s), _narrowest(right, s), walled)


def _narrowest(clear: np.ndarray, s: np.ndarray) -> float:
    """The clearance a side keeps along the whole line: the widest that every stretch of
    ``NARROW_RUN_M`` has (``clear`` per sample at ``s``, inf where no wall is in reach)."""
    step = float(s[1] - s[0]) if len(s) > 1 else NARROW_RUN_M
    k = min(len(clear), max(1, math.ceil(NARROW_RUN_M / max(step, 1e-9))))
    runs = np.lib.stride_tricks.sliding_window_view(clear, k).max(axis=1)
    return float(runs.min())
