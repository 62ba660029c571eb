"""Sim time: the Clock seam for the simulator.

``now()`` is simulated seconds; ``wait(dt)`` advances time in ticks of at most ``tick``
seconds and lets every listener (the robot bodies) integrate its motion over each tick.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

DEFAULT_TICK = 1.0 / 60.0


class SimClock:
    """Simulated time, advanced only by ``wait``; satisfies ``pmnav_bt.seams.Clock``."""

    def __init__(self, tick: float = DEFAULT_TICK, start: float = 0.0) -> None:
        if not tick > 0.0:
            raise ValueError(f"tick must be positive, got {tick}")
        self.tick = float(tick)
        self._t = float(start)
        self._listeners: list[Callable[[float], None]] = []
        self._lock = threading.Lock()

    def now(self) -> float:
        """Simulated seconds."""
        return self._t

    def add_listener(self, fn: Callable[[float], None]) -> None:
        """Call ``fn(h)`` for every tick of ``h`` seconds, before the time moves on."""
        self._listeners.append(fn)

    def remove_listener(self, fn: Callable[[float], None]) -> None:
        self._listeners.remove(fn)

    def wait(self, dt: float) -> None:
        """Advance sim time by ``dt`` seconds (negative or zero: nothing happens)."""
        with self._lock:
            remaining = float(dt)
            while remaining > 1e-12:
                h = min(self.tick, remaining)
                for fn in list(self._listeners):
                    fn(h)
                self._t += h
                remaining -= h
