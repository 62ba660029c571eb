"""ROS time: the Clock seam on the robot.

``now()`` is the node's clock (system time, or ``/clock`` when the node runs with
``use_sim_time``). ``wait(dt)`` is a rate: it sleeps until ``dt`` after the end of
the previous wait, so a tree ticked as ``tick(); wait(period)`` keeps its period
whatever a tick costs (when it falls behind by more than a period it starts again
from now instead of bursting). ``interrupt()`` ends a wait at once (shutdown, a new
goal); the interrupt stays set until ``clear()``.
"""

from __future__ import annotations

import threading

SIM_TIME_POLL_S = 0.02  # how often a wait re-reads a /clock driven clock


class RosClock:
    """Satisfies ``pmnav_bt.seams.Clock`` with a node's ROS clock."""

    def __init__(self, node) -> None:
        self._clock = node.get_clock()
        self._interrupt = threading.Event()
        self._deadline: float | None = None

    def now(self) -> float:
        """Seconds on the node's clock."""
        return self._clock.now().nanoseconds * 1e-9

    def _sim_time(self) -> bool:
        try:
            return bool(self._clock.ros_time_is_active)
        except AttributeError:  # a steady or system clock
            return False

    def wait(self, dt: float) -> None:
        """Sleep until ``dt`` after the previous deadline (rate semantics), or an interrupt."""
        now = self.now()
        base = self._deadline if self._deadline is not None else now
        deadline = base + max(0.0, float(dt))
        if deadline < now:  # fell behind: do not burst to catch up
            deadline = now + max(0.0, float(dt))
        self._deadline = deadline
        poll = SIM_TIME_POLL_S if self._sim_time() else None
        while not self._interrupt.is_set():
            remaining = deadline - self.now()
            if remaining <= 0.0:
                return
            self._interrupt.wait(remaining if poll is None else min(remaining, poll))

    def reset(self) -> None:
        """Forget the rate's phase (the next wait counts from now)."""
        self._deadline = None

    def interrupt(self) -> None:
        self._interrupt.set()

    def clear(self) -> None:
        self._interrupt.clear()
        self._deadline = None

    @property
    def interrupted(self) -> bool:
        return self._interrupt.is_set()
