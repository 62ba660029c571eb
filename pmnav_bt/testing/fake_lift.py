"""A scripted lift system (``seams.Lift``) on a ``FakeClock``, for the lift subtree's tests.

``FakeLift`` answers every request after ``come_s`` clock seconds: the cabin is at the
level asked and its door open, the lift's state saying so, held for the session until it
asks for another level or ends (``release``). What it can be told to do wrong:

- ``never``: it never comes (the state keeps its door shut where it stands);
- ``full_times``: the first so many calls are answered by a cabin with no room in it:
  people standing across its middle (``FakeObstacle``s behind ``doorway``, drawn in a
  ``FakeBase``'s depth frames; they leave with the cabin when the session ends);
- ``wrong_level``: a ride with the robot in the cabin ends on this level, while the
  lift's state says it reached the one asked (``true_level``: where the cabin really is).

Core module: no py_trees, pybullet or rclpy.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pmnav_bt.map.lift_doorway import Doorway
from pmnav_bt.seams import LiftDoor, LiftMotion, LiftState
from pmnav_bt.testing.doubles import FakeBase, FakeClock, FakeObstacle

# The people of a full cabin: five abreast across its middle, wall to wall.
CROWD = (-0.8, -0.4, 0.0, 0.4, 0.8)  # metres across the cabin from its middle


@dataclass
class FakeLift:
    """One lift, ``name``, serving ``levels``, its cabin first at ``at`` (see the module)."""

    clock: FakeClock
    levels: tuple[str, ...] = ("L1", "L2")
    at: str | None = None  # None: the last of ``levels``
    name: str = "lift1"
    come_s: float = 10.0
    never: bool = False
    full_times: int = 0
    leave_s: float = 0.0
    wrong_level: str | None = None
    base: FakeBase | None = None
    doorway: Doorway | None = None
    requests: list[tuple[float, str, str]] = field(default_factory=list)  # (t, level, session)
    releases: list[tuple[float, str]] = field(default_factory=list)  # (t, session)

    def __post_init__(self) -> None:
        self.at = self.levels[-1] if self.at is None else self.at
        if self.at not in self.levels:
            raise ValueError(f"{self.name} starts at {self.at!r}, not one of {self.levels}")
        self.true_level = self.at
        self._said = self.at  # the level the state reports
        self._door = LiftDoor.CLOSED
        self._motion = LiftMotion.STOPPED
        self._session = ""
        self._dest = self.at
        self._due: float | None = None
        self._calls = 0
        self._riding = False  # the request in hand moves the robot with the cabin
        self._crowd: list[FakeObstacle] = []
        self._shuts: float | None = None  # a cabin let go: when its door shuts
        self.clock.on_wait(self._advance)

    # -- seams.Lift --------------------------------------------------------------------------

    def request(self, lift: str, level: str, session: str) -> None:
        self._check(lift)
        if level not in self.levels:
            raise ValueError(f"{self.name} does not serve level {level!r}")
        self.requests.append((self.clock.now(), level, session))
        here = self._said == level and self._door == LiftDoor.OPEN
        if here and (self._session == session or self._shuts is not None):
            self._session, self._shuts = session, None  # the same cabin, held again
            return
        self._riding = self._session == session and self._door == LiftDoor.OPEN
        if self._session != session:
            self._calls += 1
        self._session = session
        self._dest = level
        self._door = LiftDoor.CLOSED
        if self.never:
            return
        order = self.levels.index(level) - self.levels.index(self._said)
        self._motion = LiftMotion.UP if order > 0 else LiftMotion.DOWN
        self._due = self.clock.now() + self.come_s

    def release(self, lift: str, session: str) -> None:
        self._check(lift)
        self.releases.append((self.clock.now(), session))
        if session != self._session:
            return
        self._session = ""
        self._due = None
        self._motion = LiftMotion.STOPPED
        if self._door == LiftDoor.OPEN and self.leave_s > 0.0:
            self._shuts = self.clock.now() + self.leave_s
            return
        self._leave()

    def _leave(self) -> None:
        """The door shuts; the people of a full cabin leave with it."""
        self._door = LiftDoor.CLOSED
        self._shuts = None
        for person in self._crowd:
            self.base.obstacles.remove(person)
        self._crowd = []

    def state(self, lift: str) -> LiftState | None:
        self._check(lift)
        return LiftState(
            lift=self.name,
            current_level=self._said,
            destination_level=self._dest,
            door=self._door,
            motion=self._motion,
            session=self._session,
            available_levels=self.levels,
            stamp=self.clock.now(),
        )

    # -- the script ---------------------------------------------------------------------------

    def _check(self, lift: str) -> None:
        if lift != self.name:
            raise ValueError(f"no lift {lift!r} here (this is {self.name!r})")

    def _advance(self, dt: float) -> None:
        if self._shuts is not None and self.clock.now() + dt >= self._shuts:
            self._leave()
        if self._due is None or self.clock.now() + dt < self._due:
            return
        self._due = None
        self._said = self._dest
        self.true_level = self.wrong_level if self._riding and self.wrong_level else self._dest
        self._motion = LiftMotion.STOPPED
        self._door = LiftDoor.OPEN
        full = not self._riding and self._calls <= self.full_times
        if full and self.base is not None and self.doorway is not None:
            (x, y), (ux, uy) = self.doorway.cabin_centre(), self.doorway.into
            self._crowd = [FakeObstacle.standing(x - uy * a, y + ux * a, 0.3) for a in CROWD]
            self.base.obstacles.extend(self._crowd)
