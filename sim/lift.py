"""The simulator's lift system (``seams.Lift``): cabins that come when called, open their
doors, ride between level worlds with the robot in them, and sometimes come full.

Each lift (``SimLift.add``) has a cabin on every level it serves (``sim/scene/lifts.py``:
the recess behind the lift landmark's doors in that level's ``SimWorld``). A request
for a level, by a session, is answered as a building's lift answers a call: after a
call delay (the lift serves other calls first: up to ``call_delay_s``, drawn per call
from the world's seeded stream ``rng("lift")``), the door shuts if it stood open
(``door_s``), the cabin rides (``ride_s_per_level`` a level), the door opens
(``door_s``) and stays open while the session holds the lift at that level. A session's
request for another level from inside the cabin shuts the door and rides at once. When
the session ends (``release``) the door shuts after ``dwell_s``. The timings
(``LiftTiming``, by default a hospital bed lift's) are ``pmnav_bt/lift_timing.py``'s,
the same lift as the simulated lift node's (``hardware/lift_bank.py``).

A call is answered full with probability ``world.lift_full_p``, drawn for each arrival:
the cabin opens with a cart in it (people with their trolley, ``Cabin.fill``) and, let
go, rides off with it to another level. A call while its doors are still open or
shutting opens them again on the same cabin, cart and all (no new arrival, no draw).
A robot standing on the cabin's floor when it leaves rides with it: at
the far level the lift hands it to ``rider.carry`` at the same place in that level's
cabin. Time is the simulation's clock (a clock listener), never wall time.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol

import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import se2_compose, se2_inverse
from pmnav_bt.lift_timing import BED_LIFT, LiftTiming
from pmnav_bt.seams import LiftDoor, LiftMotion, LiftState, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.scene.lifts import Cabin


class LiftError(PmNavError):
    """A request names a lift or a level the lift system does not have."""


class Rider(Protocol):
    """What the lift needs of the robot: which level's world it is in, where in it, and
    how to move it to another level's world (``sim.levels.LevelBody``)."""

    level: str

    def world_pose(self) -> Pose2D: ...

    def carry(self, level: str, pose: Pose2D) -> None: ...


class Phase(str, Enum):
    """What a lift is doing."""

    IDLE = "idle"  # at a level, door shut, nothing asked
    CALLED = "called"  # serving other calls first (the call delay)
    CLOSING = "closing"
    RIDING = "riding"
    OPENING = "opening"
    OPEN = "open"


@dataclass
class _Car:
    """One lift's state: where its cabin is and what it is doing until ``until``."""

    id: str
    name: str
    cabins: dict[str, Cabin]  # by level, in the levels' order
    level: str
    dest: str
    phase: Phase = Phase.IDLE
    until: float = math.inf
    session: str = ""
    full: bool = False
    carrying: bool = False
    levels: tuple[str, ...] = field(default=())


class SimLift:
    """The lift system of a simulated building of several levels (``seams.Lift``; see the
    module). ``clock``: the simulation's; ``rider``: the robot; ``full_p``: how often a
    call is answered full; ``rng``: the seeded stream of call delays and full cabins;
    ``timing``: how long the lift takes."""

    def __init__(
        self,
        clock: SimClock,
        rider: Rider,
        rng: np.random.Generator,
        full_p: float = 0.0,
        timing: LiftTiming = BED_LIFT,
    ) -> None:
        self.clock, self.rider, self.rng, self.full_p = clock, rider, rng, float(full_p)
        self.timing = timing
        self._cars: dict[str, _Car] = {}
        self.full_calls = 0  # calls answered by a full cabin (an evaluation's "lift full met")
        clock.add_listener(self._advance)

    def add(self, lift: str, name: str, cabins: Mapping[str, Cabin], at: str) -> None:
        """A lift ``lift`` (``name`` as people call it) with its cabin on each level it
        serves (``cabins``, in the levels' order from the lowest), standing at ``at``."""
        if at not in cabins:
            raise LiftError(f"lift {lift}: it does not serve level {at!r}")
        self._cars[lift] = _Car(lift, name, dict(cabins), at, at, levels=tuple(cabins))

    def close(self) -> None:
        """Stop following the clock."""
        self.clock.remove_listener(self._advance)

    # -- seams.Lift ----------------------------------------------------------------------------

    def request(self, lift: str, level: str, session: str) -> None:
        car = self._car(lift, level)
        call = car.session != session
        car.session = session
        if car.level == level and car.phase in (Phase.OPENING, Phase.OPEN):
            return  # here already: the door stays open for the session
        car.dest = level
        now = self.clock.now()
        if call and car.level == level and car.phase == Phase.CLOSING:
            # The doors shutting here open again on the same cabin, its load and all: a
            # new arrival (full or not, drawn) answers only a call after they shut.
            car.phase, car.until = Phase.OPENING, now + self.timing.door_s
            return
        if call:
            car.full = bool(self.rng.random() < self.full_p)
            self.full_calls += car.full
            delay = float(self.rng.uniform(0.0, self.timing.call_delay_s))
            car.phase, car.until = Phase.CALLED, now + delay
        elif car.phase == Phase.OPEN:
            car.phase, car.until = Phase.CLOSING, now + self.timing.door_s
            car.cabins[car.level].set_door(False)

    def release(self, lift: str, session: str) -> None:
        car = self._car(lift)
        if session != car.session:
            return
        car.session = ""
        if car.phase == Phase.CALLED:
            car.phase, car.until = Phase.IDLE, math.inf
        elif car.phase == Phase.OPEN:
            car.until = self.clock.now() + self.timing.dwell_s

    def state(self, lift: str) -> LiftState | None:
        car = self._car(lift)
        door = {Phase.OPEN: LiftDoor.OPEN, Phase.OPENING: LiftDoor.MOVING}.get(
            car.phase, LiftDoor.MOVING if car.phase == Phase.CLOSING else LiftDoor.CLOSED
        )
        motion = LiftMotion.STOPPED
        if car.phase == Phase.RIDING:
            up = car.levels.index(car.dest) > car.levels.index(car.level)
            motion = LiftMotion.UP if up else LiftMotion.DOWN
        return LiftState(
            lift=car.id,
            current_level=car.level,
            destination_level=car.dest,
            door=door,
            motion=motion,
            session=car.session,
            available_levels=car.levels,
            stamp=self.clock.now(),
        )

    # -- the lift's own time ---------------------------------------------------------------------

    def _car(self, lift: str, level: str | None = None) -> _Car:
        car = self._cars.get(lift)
        if car is None:
            raise LiftError(f"no lift {lift!r} here; lifts: {', '.join(sorted(self._cars))}")
        if level is not None and level not in car.cabins:
            raise LiftError(f"{car.name} does not serve level {level!r}")
        return car

    def _advance(self, h: float) -> None:
        """Clock listener: end each lift's phase whose time is up."""
        now = self.clock.now() + h
        for car in self._cars.values():
            while car.until <= now:
                self._next(car, car.until)

    def _next(self, car: _Car, t: float) -> None:
        cabin = car.cabins[car.level]
        if car.phase == Phase.CALLED:
            car.phase, car.until = self._leave_or_open(car, t)
        elif car.phase == Phase.CLOSING:
            car.phase, car.until = self._leave_or_open(car, t, closed=True)
        elif car.phase == Phase.RIDING:
            self._arrive(car)
            car.phase, car.until = Phase.OPENING, t + self.timing.door_s
        elif car.phase == Phase.OPENING:
            cabin.set_door(True)
            dwell = self.timing.dwell_s if not car.session else math.inf
            car.phase, car.until = Phase.OPEN, t + dwell
        elif car.phase == Phase.OPEN:  # no one holds it: shut; people riding on go on
            cabin.set_door(False)
            if car.full:
                car.dest = self._elsewhere(car)
            car.phase, car.until = Phase.CLOSING, t + self.timing.door_s
        else:
            car.until = math.inf

    def _leave_or_open(self, car: _Car, t: float, closed: bool = False) -> tuple[Phase, float]:
        """The door shut (or the call's delay over): ride to the destination, or open here."""
        cabin = car.cabins[car.level]
        if cabin.is_open:
            cabin.set_door(False)
            return Phase.CLOSING, t + self.timing.door_s
        if car.dest == car.level:
            if closed and not car.session:
                return Phase.IDLE, math.inf
            if car.full and not cabin.cart:
                cabin.fill()  # they got in on the way: no room for the robot
            return Phase.OPENING, t + self.timing.door_s
        rider = self.rider
        car.carrying = rider.level == car.level and cabin.holds(*_xy(rider.world_pose()))
        cabin.empty()
        storeys = abs(car.levels.index(car.dest) - car.levels.index(car.level))
        return Phase.RIDING, t + self.timing.ride_s_per_level * storeys

    def _arrive(self, car: _Car) -> None:
        """At the destination: the robot carried into this level's cabin, the cart too."""
        here, there = car.cabins[car.level], car.cabins[car.dest]
        car.level = car.dest
        if car.carrying:
            f0, f1 = here.frame, there.frame
            rel = se2_compose(
                se2_inverse((f0.x, f0.y, f0.yaw)), _tuple(self.rider.world_pose())
            )
            x, y, yaw = se2_compose((f1.x, f1.y, f1.yaw), rel)
            self.rider.carry(car.level, Pose2D(x, y, yaw))
            car.carrying = False
        elif car.full and not car.session:
            car.full = False  # the people got out where they were going
        if car.full:
            there.fill()

    def _elsewhere(self, car: _Car) -> str:
        others: Sequence[str] = [lv for lv in car.levels if lv != car.level]
        return others[int(self.rng.integers(len(others)))] if others else car.level


def _xy(p: Pose2D) -> tuple[float, float]:
    return p.x, p.y


def _tuple(p: Pose2D) -> tuple[float, float, float]:
    return p.x, p.y, p.yaw
