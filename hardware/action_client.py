"""An action client that may send goals from a thread other than its executor's.

rclpy's ``ActionClient`` (7.1, ROS 2 Jazzy) sends a request and only then records its
sequence number with the future that waits for the answer. A client spun by a background
executor (``RosRuntime``) and called from another thread (the ``pmnav-goal`` command, a
test) can have its answer taken and handled by the executor in between: the answer is
dropped as "unexpected" ("There may be more than one action server") and the future
never completes, so an accepted goal looks unanswered (ros2/rclpy#1123; upstream's fix
takes a lock round both sides, as here, and is not in the Jazzy wheels).

``ThreadSafeActionClient`` holds one lock while a request is sent and recorded, and while
the executor takes answers off the wire, so an answer is only looked up once its request
is on record.
"""

from __future__ import annotations

import threading

from rclpy.action import ActionClient


class ThreadSafeActionClient(ActionClient):
    """``rclpy.action.ActionClient`` whose goal, cancel and result requests may be sent
    from any thread while an executor spins it."""

    def __init__(self, *args, **kwargs) -> None:
        self._requests_lock = threading.RLock()
        super().__init__(*args, **kwargs)

    def take_data(self):
        with self._requests_lock:
            return super().take_data()

    def send_goal_async(self, goal, feedback_callback=None, goal_uuid=None):
        with self._requests_lock:
            return super().send_goal_async(goal, feedback_callback, goal_uuid)

    def _cancel_goal_async(self, goal_handle):
        with self._requests_lock:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle):
        with self._requests_lock:
            return super()._get_result_async(goal_handle)
