"""Open-RMF's lift protocol on ROS 2: the topics, and conversions between rmf_lift_msgs and
the core's ``seams.LiftState``.

A robot (RMF: its fleet adapter, through the lift supervisor) publishes
``rmf_lift_msgs/LiftRequest`` on ``/lift_requests``; each lift's adapter publishes its
``rmf_lift_msgs/LiftState`` on ``/lift_states`` (RMF's simulated lifts: at 2 Hz and on
every change). Both topics are in the root namespace, so a robot started in its own
namespace still talks to the building's lifts. QoS as Open-RMF's: ``qos.lift_requests()``
and ``qos.lift_states()``.

``rmf_lift_msgs`` is not on PyPI: ``interfaces/build.sh`` builds it from Open-RMF's
definitions (``interfaces/rmf_lift_msgs``). Nothing here imports it at module import time.
"""

from __future__ import annotations

from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware.messages import sec_to_stamp, stamp_to_sec
from pmnav_bt.seams import LiftDoor, LiftMotion, LiftState

REQUESTS_TOPIC = "/lift_requests"
STATES_TOPIC = "/lift_states"

# rmf_lift_msgs/LiftState's door_state and motion_state values.
DOORS = {0: LiftDoor.CLOSED, 1: LiftDoor.MOVING, 2: LiftDoor.OPEN}
MOTIONS = {0: LiftMotion.STOPPED, 1: LiftMotion.UP, 2: LiftMotion.DOWN, 3: LiftMotion.UNKNOWN}


def messages():
    """(LiftRequest, LiftState) of rmf_lift_msgs; a PmNavError naming the fix without it."""
    try:
        from rmf_lift_msgs.msg import LiftRequest
        from rmf_lift_msgs.msg import LiftState as LiftStateMsg
    except ImportError:
        raise PmNavError(
            "rmf_lift_msgs is not built: run interfaces/build.sh (part of make setup)"
        ) from None
    return LiftRequest, LiftStateMsg


def available() -> bool:
    try:
        messages()
    except PmNavError:
        return False
    return True


def state_from_message(msg) -> LiftState:
    """rmf_lift_msgs/LiftState -> LiftState (an unknown door or motion value reads as
    moving / unknown: a state the robot must not drive into a cabin on)."""
    return LiftState(
        lift=msg.lift_name,
        current_level=msg.current_floor,
        destination_level=msg.destination_floor,
        door=DOORS.get(int(msg.door_state), LiftDoor.MOVING),
        motion=MOTIONS.get(int(msg.motion_state), LiftMotion.UNKNOWN),
        session=msg.session_id,
        available_levels=tuple(msg.available_floors),
        stamp=stamp_to_sec(msg.lift_time),
    )


def state_message(state: LiftState, stamp=None):
    """LiftState -> rmf_lift_msgs/LiftState in AGV mode (the mode this project's lifts
    serve); ``stamp``: a builtin_interfaces/Time (default: the state's own stamp)."""
    _, msg_type = messages()
    msg = msg_type()
    msg.lift_time = sec_to_stamp(state.stamp) if stamp is None else stamp
    msg.lift_name = state.lift
    msg.available_floors = list(state.available_levels)
    msg.current_floor = state.current_level
    msg.destination_floor = state.destination_level
    msg.door_state = _code(DOORS, state.door)
    msg.motion_state = _code(MOTIONS, state.motion)
    msg.available_modes = [msg_type.MODE_HUMAN, msg_type.MODE_AGV]
    msg.current_mode = msg_type.MODE_AGV
    msg.session_id = state.session
    return msg


def request_message(lift: str, level: str, session: str, stamp, end: bool = False):
    """An AGV-mode request for ``lift`` to ``level`` with the door open there, for
    ``session``; ``end``: REQUEST_END_SESSION instead (``level``: where the lift is)."""
    msg_type, _ = messages()
    msg = msg_type()
    msg.lift_name = lift
    msg.request_time = stamp
    msg.session_id = session
    msg.request_type = msg_type.REQUEST_END_SESSION if end else msg_type.REQUEST_AGV_MODE
    msg.destination_floor = level
    msg.door_state = msg_type.DOOR_CLOSED if end else msg_type.DOOR_OPEN
    return msg


def _code(table: dict, value) -> int:
    return next(k for k, v in table.items() if v == value)
