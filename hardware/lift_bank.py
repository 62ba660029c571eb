"""A bank of simulated lifts in time, as an Open-RMF lift adapter drives real ones: the
model behind ``pmnav-sim-lift`` (``sim_lift_node.py``). It implements ``seams.Lift``, so
it also serves as a lift system in one process.

What one lift does (Open-RMF's AGV mode, the mode a robot uses):

- **Sessions.** The first request to an idle lift grants it to that request's session;
  while a session holds the lift, requests of other sessions are not answered (the
  requester sees another ``session`` in the state and asks again, as RMF's lift
  supervisor does) until the holder ends its session (``release``). The holder may ask
  again with another level: that moves the cabin.
- **The call.** A granted call waits a seeded delay, uniform in ``[0, call_delay_s]``,
  before the cabin moves: the lift finishing the calls of the people already in it.
- **The ride.** The door closes (``door_s``: how long the door takes to close or to open),
  the cabin moves ``ride_s_per_level`` per level (the timings: ``pmnav_bt/lift_timing.py``,
  the same lift as the simulator's ``SimLift``), stops at the destination, and the door
  opens and stays open while the session holds the lift there (AGV mode: the robot needs
  time to drive in or out). After the session ends, the door stays open ``dwell_s`` and
  then closes, as a lift's door does after its last passenger.
- **The state** (``state``): the level nearest to the cabin, the destination, the door
  (closed, moving or open), the motion (up, down, stopped), the session, the levels.

Time comes from ``clock`` (seconds); ``step()`` advances every lift to ``clock()``.
Each lift serves its own levels, listed from the lowest to the highest.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from pmnav_bt.errors import PmNavError
from pmnav_bt.lift_timing import BED_LIFT, LiftTiming
from pmnav_bt.seams import LiftDoor, LiftMotion, LiftState


@dataclass
class _Cabin:
    """One lift's motion: ``position`` in level indices (0 = the lowest level), ``door``
    how far open (0 closed .. 1 open)."""

    name: str
    levels: tuple[str, ...]  # lowest first
    position: float
    destination: int
    door: float = 0.0
    want_open: bool = False  # the door the session asked for at its destination
    session: str = ""
    start_at: float = 0.0  # the call's delay: the cabin waits until then
    close_at: float = 0.0  # after a release: the door closes then (the dwell)
    refused: str = ""  # the last session refused while this one holds the lift (logged once)


class LiftBank:
    """Simulated lifts: ``lifts`` maps each lift's name to the levels it serves, lowest
    first; ``timing`` how long each takes; see the module doc."""

    def __init__(
        self,
        lifts: Mapping[str, Sequence[str]],
        *,
        start_level: str = "",
        timing: LiftTiming = BED_LIFT,
        seed: int = 0,
        clock: Callable[[], float] = time.monotonic,
        log: Callable[[str], None] = lambda _line: None,
    ) -> None:
        if not lifts:
            raise PmNavError("a lift bank needs at least one lift")
        if not all(lifts):
            raise PmNavError(f"lift names must not be empty: {list(lifts)}")
        for name, levels in lifts.items():
            levels = tuple(levels)
            if not levels or not all(levels) or len(set(levels)) < len(levels):
                raise PmNavError(
                    f"lift {name}: level names must be unique and not empty: {list(levels)}"
                )
            if start_level and start_level not in levels:
                raise PmNavError(f"lift {name}: start level {start_level!r} is not one of "
                                 f"{list(levels)}")  # fmt: skip
        self.timing = timing
        self.clock, self.log = clock, log
        self._t = clock()
        self._cabins = {}
        for name, levels in lifts.items():
            start = tuple(levels).index(start_level) if start_level else 0
            self._cabins[name] = _Cabin(name, tuple(levels), float(start), start)
        # one seeded stream per lift: a lift's delays do not depend on the others' calls
        self._rng = {n: random.Random(f"{seed}/{n}") for n in lifts}

    @property
    def lifts(self) -> tuple[str, ...]:
        return tuple(self._cabins)

    # -- the Lift seam ----------------------------------------------------------------------

    def request(self, lift: str, level: str, session: str, door_open: bool = True) -> None:
        """``session`` asks ``lift`` to ``level`` with its door open there (or closed);
        unanswered while another session holds the lift. Unknown lifts and levels are
        logged and ignored, as a lift adapter does."""
        self.step()
        c = self._cabin(lift)
        if c is None or not session:
            return
        if level not in c.levels:
            self.log(f"lift {lift}: no level {level!r} (levels {', '.join(c.levels)})")
            return
        if c.session and c.session != session:
            if c.refused != session:  # a requester asks again on every state: log it once
                c.refused = session
                self.log(f"lift {lift}: busy with session {c.session!r}; {session!r} must wait")
            return
        dest = c.levels.index(level)
        if not c.session:
            c.session, c.refused = session, ""
            c.start_at = self._t + self._rng[lift].uniform(0.0, self.timing.call_delay_s)
            self.log(f"lift {lift}: session {session!r} granted, to {level}")
        elif dest != c.destination:
            self.log(f"lift {lift}: session {session!r} to {level}")
        c.destination, c.want_open = dest, door_open

    def release(self, lift: str, session: str) -> None:
        """End ``session`` on ``lift`` (the holder only); the door closes after the dwell."""
        self.step()
        c = self._cabin(lift)
        if c is None or not session or c.session != session:
            return
        c.session, c.want_open = "", False
        c.close_at = self._t + self.timing.dwell_s
        self.log(f"lift {lift}: session {session!r} ended")

    def state(self, lift: str) -> LiftState | None:
        self.step()
        c = self._cabins.get(lift)
        if c is None:
            return None
        if c.door <= 0.0:
            door = LiftDoor.CLOSED
        elif c.door >= 1.0:
            door = LiftDoor.OPEN
        else:
            door = LiftDoor.MOVING
        motion = LiftMotion.STOPPED
        started = not c.session or self._t >= c.start_at
        if c.position != c.destination and c.door <= 0.0 and started:
            motion = LiftMotion.UP if c.destination > c.position else LiftMotion.DOWN
        return LiftState(
            lift=lift,
            current_level=c.levels[int(c.position + 0.5)],  # the nearest level
            destination_level=c.levels[c.destination],
            door=door,
            motion=motion,
            session=c.session,
            available_levels=c.levels,
            stamp=self._t,
        )

    # -- time -------------------------------------------------------------------------------

    def step(self) -> None:
        """Advance every lift to ``clock()``."""
        now = self.clock()
        t0, self._t = self._t, max(self._t, now)
        for c in self._cabins.values():
            self._advance(c, t0, self._t)

    def _advance(self, c: _Cabin, t0: float, t1: float) -> None:
        """``c`` from ``t0`` to ``t1``: nothing for a granted session before its call's
        delay is over; the door stays open through the dwell after a release; the door
        closes before the cabin moves, and opens at the destination when asked to."""
        if c.session:
            t0 = max(t0, c.start_at)
        elif c.position == c.destination:
            t0 = max(t0, c.close_at)
        left, door_s = t1 - t0, self.timing.door_s
        if left <= 0.0:
            return
        if c.position == c.destination and c.session and c.want_open:
            c.door = 1.0 if door_s == 0.0 else min(1.0, c.door + left / door_s)
            return
        need = c.door * door_s
        if left < need:
            c.door -= left / door_s
            return
        c.door, left = 0.0, left - need
        if c.position != c.destination:
            gap = c.destination - c.position
            need = abs(gap) * self.timing.ride_s_per_level
            if left < need:
                c.position += (1.0 if gap > 0 else -1.0) * left / self.timing.ride_s_per_level
                return
            c.position, left = float(c.destination), left - need
            self._advance(c, t1 - left, t1)  # arrived: the door opens in the time left

    def _cabin(self, lift: str) -> _Cabin | None:
        c = self._cabins.get(lift)
        if c is None:
            self.log(f"no lift {lift!r} here (lifts {', '.join(self._cabins)})")
        return c
