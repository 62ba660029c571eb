"""``RosLiftClient``: the building's lifts over Open-RMF's lift protocol (``seams.Lift``).

Requests go out on ``/lift_requests`` (rmf_lift_msgs/LiftRequest, AGV mode, door open at
the destination); states come in on ``/lift_states`` and the latest of each lift is kept.
Like RMF's lift supervisor, the client holds each lift's current request and sends it
again whenever a state disagrees with it (another destination, the door not as asked,
another session): a lift adapter takes requests as they come and forgets the ones it could
not serve, so a request lost before discovery, or refused while another session held the
lift, is answered once the lift hears it again after that session ends. A release
(REQUEST_END_SESSION) is sent again while the lift still names the released session.

The callbacks run in the executor's thread, ``request``/``release``/``state`` in the
tree's: one lock guards what they share.
"""

from __future__ import annotations

import threading

from pmnav_bt.hardware import qos, rmf_lift
from pmnav_bt.seams import LiftDoor, LiftState


class RosLiftClient:
    """``seams.Lift`` on an rclpy ``node`` (rmf_lift_msgs must be built)."""

    def __init__(self, node) -> None:
        request_type, state_type = rmf_lift.messages()
        self.node = node
        self._lock = threading.Lock()
        self._states: dict[str, LiftState] = {}
        self._wanted: dict[str, tuple[str, str]] = {}  # lift -> (level, session)
        self._releasing: dict[str, str] = {}  # lift -> session being ended
        self._pub = node.create_publisher(
            request_type, rmf_lift.REQUESTS_TOPIC, qos.lift_requests()
        )
        node.create_subscription(
            state_type, rmf_lift.STATES_TOPIC, self._on_state, qos.lift_states()
        )

    # -- the Lift seam ----------------------------------------------------------------------

    def request(self, lift: str, level: str, session: str) -> None:
        with self._lock:
            self._wanted[lift] = (level, session)
            self._releasing.pop(lift, None)
        self._send(lift, level, session)

    def release(self, lift: str, session: str) -> None:
        with self._lock:
            if self._wanted.get(lift, ("", ""))[1] == session:
                del self._wanted[lift]
            self._releasing[lift] = session
            s = self._states.get(lift)
        self._send(lift, s.current_level if s else "", session, end=True)

    def state(self, lift: str) -> LiftState | None:
        with self._lock:
            return self._states.get(lift)

    def summary(self) -> dict[str, str]:
        """What each lift last said, one line a lift, for the node's status and
        /diagnostics: ``at L1, to L3, door closed, up, session /pmnav``."""
        with self._lock:
            states = list(self._states.values())
        return {
            s.lift: f"at {s.current_level}, to {s.destination_level}, door {s.door.value}, "
            f"{s.motion.value}, session {s.session or 'none'}"
            for s in states
        }

    # -- the topics -------------------------------------------------------------------------

    def _send(self, lift: str, level: str, session: str, end: bool = False) -> None:
        stamp = self.node.get_clock().now().to_msg()
        self._pub.publish(rmf_lift.request_message(lift, level, session, stamp, end=end))

    def _on_state(self, msg) -> None:
        s = rmf_lift.state_from_message(msg)
        again: tuple[str, str, bool] | None = None
        with self._lock:
            self._states[s.lift] = s
            wanted = self._wanted.get(s.lift)
            ending = self._releasing.get(s.lift)
            if wanted is not None and _disagrees(s, *wanted):
                again = (wanted[0], wanted[1], False)
            elif ending is not None:
                if s.session == ending:
                    again = (s.current_level, ending, True)
                else:
                    del self._releasing[s.lift]
        if again is not None:
            self._send(s.lift, *again[:2], end=again[2])


def _disagrees(s: LiftState, level: str, session: str) -> bool:
    """The state is not (yet) what the request asks: RMF's lift supervisor's test."""
    at_level = s.destination_level == level or (
        s.current_level == level and not s.destination_level
    )
    return not at_level or s.door != LiftDoor.OPEN or s.session != session
