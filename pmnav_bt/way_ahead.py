"""What a drive does when something stands in its way: wait, go round, or give up.

Nav2's answer to a person in front of a robot is patience, not a push: stop, wait a
while for the way to clear, and only then try something else. A drive that sees
something on the floor ahead (``behaviours/motion.py``) stops and holds (``Hold``);
every watch frame after that (one a second) is judged (``judge``):

- the way is clear again (the person walked on, a door was opened): go on;
- it stood still over two frames (clutter: a bin, a bed, a trolley) and there is room
  beside it: go round it at once, as the drive always did;
- otherwise wait, up to ``PATIENCE_S``; then go round it where there is room (pass the
  person who stays), else give up: the way is shut (``WayShut``), and the tree's
  recovery and replan take over.

Something is known to move by where it stands on the floor shifting between watch
frames (``perception/movers.py``; from the frame before the stop on, so a person who
walked up and stopped counts as moving); in the simulator that is how a person is told
from a wall, with no labels read. A person who stood quite still all along is not told
apart (they are passed like clutter, with the detour's margin), and nothing that fills
the way is ever driven into.

``PATIENCE_S`` (10 s): long enough for a person who stopped in the way to step aside
or walk on (people in the simulator stop 0.8 m from the robot and turn back after 2 s;
those who pause to talk stand 3-10 s), short enough that a corridor closed for good
costs little; Nav2's ``Wait`` recovery waits 5 s, and its controller's progress checker
gives a robot 10 s to move before it fails.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from pmnav_bt.failures import Failure
from pmnav_bt.seams import Observation

PATIENCE_S = 10.0


class Verdict(str, Enum):
    """What a drive held up by something in its way does next."""

    GO_ON = "go on"  # the way is clear
    WAIT = "wait"  # stay stopped and look again
    GO_ROUND = "go round"  # take the detour beside it
    GIVE_UP = "give up"  # the way is shut: fail, recover, replan


@dataclass
class Hold:
    """A drive stopped for something ``free`` m ahead since ``since`` (clock s): the
    frames seen since (``last``), how many, whether anything in the way moved (from the
    frame before the stop on), and the latest map point beside it that a frame showed
    open (``room``; None: none yet). The robot stands still while held, so a point one
    frame showed open stays a way round when the next, with the person stepping about,
    shows none."""

    since: float
    free: float
    last: Observation
    room: tuple[float, float] | None = None
    frames: int = 1
    moving: bool = False

    def seen(
        self, obs: Observation, free: float, room: tuple[float, float] | None, moved: bool | None
    ) -> None:
        """Another frame with the way still shut, ``free`` m ahead, ``room`` beside it (or
        None); ``moved``: whether something moved since the last (None: cannot tell)."""
        self.moving = self.moving or bool(moved)
        self.free = min(self.free, free)
        self.room = room if room is not None else self.room
        self.last = obs
        self.frames += 1

    def held_for(self, now: float) -> float:
        return now - self.since


def judge(hold: Hold, now: float, clear: bool, room_beside: bool) -> Verdict:
    """What to do after a watch frame while held (see the module's docstring)."""
    if clear:
        return Verdict.GO_ON
    if room_beside and not hold.moving and hold.frames >= 2:
        return Verdict.GO_ROUND
    if hold.held_for(now) < PATIENCE_S:
        return Verdict.WAIT
    return Verdict.GO_ROUND if room_beside else Verdict.GIVE_UP


@dataclass(frozen=True)
class WayShut:
    """A drive gave up on its way: something stood ``free`` m ahead for ``seconds`` s,
    at map point ``point``; ``moving``: it moved (a person) rather than stood still (a
    barrier, a closed door). The tree's ``NoteFailure`` reads it to mark the corridor."""

    point: tuple[float, float]
    seconds: float
    moving: bool


@dataclass(frozen=True)
class BlockedWay:
    """A corridor marked blocked for the run: where it was seen shut (map ``point``: the
    plan leaves a segment the robot is on by the end on its side) and the ``failure``
    that said so (its words are the run's reason when no way round is left)."""

    point: tuple[float, float]
    failure: Failure
