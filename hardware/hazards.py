"""The Create 3's ``hazard_detection`` topic on PM-Nav's side: messages, and what they forbid.

``irobot_create_msgs/HazardDetectionVector`` carries every hazard the robot detects now,
about 60 times a second (an empty vector: none); each detection a type and, in its
header, the time and the frame of the sensor that felt it (``pmnav_bt.hazards`` places
the frames on the body). The package is not on PyPI: ``interfaces/build.sh`` builds the
two messages from iRobot's definitions, and ``message_types()`` is None where it was not
built (the body then feels nothing: one line in its log says so).

``HazardWatch`` keeps what the body felt and decides which motions a hazard forbids:

- a bump forbids driving forwards while the bumper is pressed (felt within
  ``BUMP_HOLD_S``): the body stops at once, BLOCKED; backing off and turning in place
  (a round body turning never pushes) stay allowed, or the recoveries could not leave;
- a stall stops a motion that has run ``STALL_GRACE_S`` (the wheels had time to turn)
  and was felt since that motion began: BLOCKED; a new command may try again;
- a cliff or a dropped wheel forbids every motion while it is felt and ``FAULT_HOLD_S``
  after: the body's status is FAULT, which ends the mission (the tree must never drive
  on where the floor ends; the robot's own reflexes back it off the edge).

The backup limit and object proximity detections are not acted on: the body keeps its
own backup buffer (``pmnav_bt.backup_limit``), and proximity is no contact.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Iterable

from pmnav_bt.hazards import Hazard, HazardKind, place
from pmnav_bt.seams import Pose2D

# HazardDetection.type of each kind (iRobot's constants: BACKUP_LIMIT=0 and
# OBJECT_PROXIMITY=5 are the ones not acted on).
TYPE_CODES = {
    HazardKind.BUMP: 1,
    HazardKind.CLIFF: 2,
    HazardKind.STALL: 3,
    HazardKind.WHEEL_DROP: 4,
}
BACKUP_LIMIT_CODE = 0
_KINDS = {code: kind for kind, code in TYPE_CODES.items()}

# A hazard is held for a while after its last detection: longer than the robot's period
# (16 ms) and than the gaps of a starved simulated Create 3 (20 Hz, gaps of 0.3 s seen on
# 2 busy cores), so one late message does not let the body push again.
BUMP_HOLD_S = 0.5
STALL_GRACE_S = 0.3  # ... and a stall only stops a motion older than this
FAULT_HOLD_S = 2.0  # a cliff: long enough for any tick rate to see the FAULT
SAME_PLACE_M = 0.05  # a hazard felt again this close to the last is the same one
KEPT = 200  # hazards kept for ``felt`` (the costmap reads them each tick)
FAULT_KINDS = (HazardKind.CLIFF, HazardKind.WHEEL_DROP)  # the body faults: no motion at all


def message_types():
    """(HazardDetectionVector, HazardDetection), or None where irobot_create_msgs is not
    built."""
    try:
        from irobot_create_msgs.msg import HazardDetection, HazardDetectionVector
    except ImportError:
        return None
    return HazardDetectionVector, HazardDetection


def hazards_from_message(
    msg, pose_at: Callable[[float], Pose2D], stamp_of: Callable[[object], float]
) -> list[Hazard]:
    """The detections of a HazardDetectionVector that the body acts on, each placed with
    ``pose_at`` (the odometry pose at a time) at its stamp (the vector's where a detection
    has none)."""
    default = stamp_of(msg.header.stamp)
    out = []
    for d in msg.detections:
        kind = _KINDS.get(int(d.type))
        if kind is None:
            continue
        t = stamp_of(d.header.stamp) or default
        out.append(place(kind, str(d.header.frame_id), pose_at(t), t))
    return out


def vector_message(types, detections: Iterable[tuple[int, str]], stamp, frame_id: str):
    """A HazardDetectionVector of ``(type code, sensor frame)`` detections, all at ``stamp``."""
    vector_cls, detection_cls = types
    msg = vector_cls()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    for code, frame in detections:
        d = detection_cls(type=code)
        d.header.stamp = stamp
        d.header.frame_id = frame
        msg.detections.append(d)
    return msg


class HazardWatch:
    """What the body felt (odometry frame) and the motions it forbids now. Times:
    ``now`` is the monotonic clock of arrival; a Hazard's ``stamp`` is the robot's.
    Not thread-safe: the body calls it under its lock."""

    def __init__(self) -> None:
        self._felt: deque[Hazard] = deque(maxlen=KEPT)
        self._last: dict[HazardKind, tuple[Hazard, float]] = {}  # kind: (newest, arrival)

    def feel(self, hazard: Hazard, now: float) -> None:
        """Take in one detection (the robot repeats a hazard while it lasts)."""
        self._last[hazard.kind] = (hazard, now)
        for i in range(len(self._felt) - 1, -1, -1):
            h = self._felt[i]
            if (h.kind, h.frame) == (hazard.kind, hazard.frame):
                if math.dist(h.point, hazard.point) <= SAME_PLACE_M:
                    del self._felt[i]  # the same one: kept once, with its newest stamp
                break
        self._felt.append(hazard)

    def felt(self, since: float = -math.inf) -> list[Hazard]:
        """The hazards felt with a stamp from ``since`` on, oldest first."""
        return [h for h in self._felt if h.stamp >= since]

    def fault(self, now: float) -> Hazard | None:
        """The cliff or dropped wheel held now (every motion forbidden), or None."""
        return self._held(FAULT_KINDS, FAULT_HOLD_S, now)

    def forbids(self, v: float, w: float, now: float, moving_for: float) -> Hazard | None:
        """The hazard that forbids the motion (v m/s, w rad/s) that has been under way for
        ``moving_for`` s (0: about to start), or None."""
        if v == 0.0 and w == 0.0:
            return None
        held = self.fault(now)
        if held is None and v > 0.0:
            held = self._held((HazardKind.BUMP,), BUMP_HOLD_S, now)
        if held is None and moving_for >= STALL_GRACE_S:  # felt since this motion began
            held = self._held((HazardKind.STALL,), min(BUMP_HOLD_S, moving_for), now)
        return held

    def _held(self, kinds: tuple[HazardKind, ...], hold: float, now: float) -> Hazard | None:
        """The newest hazard of ``kinds`` felt within the last ``hold`` s, or None."""
        held = [(t, h) for k, (h, t) in self._last.items() if k in kinds and now - t <= hold]
        return max(held, key=lambda th: th[0])[1] if held else None
