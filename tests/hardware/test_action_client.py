"""The action client sends goals from the caller's thread while a background executor
takes the answers: an answer taken before its request is on record must not be lost."""

from __future__ import annotations

import threading
import time

import pytest

from pmnav_bt.hardware.action_server import action_type

pytestmark = [
    pytest.mark.timeout(120),
    pytest.mark.skipif(action_type() is None, reason="pmnav_interfaces not built"),
]


class _SlowToRecord(dict):
    """The client's table of pending goal requests, slow to look up from the sending
    thread: it widens the window between "request sent" and "request on record" to
    0.5 s, in which the executor thread takes the server's answer."""

    def __init__(self, sender: threading.Thread):
        super().__init__()
        self.sender = sender

    def __contains__(self, key) -> bool:
        if threading.current_thread() is self.sender:
            time.sleep(0.5)
        return super().__contains__(key)


def test_an_answer_taken_before_its_request_is_recorded_still_completes_the_goal(domain_id):
    from rclpy.action import ActionServer
    from rclpy.node import Node

    from pmnav_bt.hardware.action_client import ThreadSafeActionClient
    from pmnav_bt.hardware.runtime import RosRuntime

    kind = action_type()
    rt = RosRuntime(args=[], domain_id=domain_id)
    server_node = Node("race_server", context=rt.context)

    def execute(gh):
        gh.succeed()
        return kind.Result(room_id="room1")

    ActionServer(server_node, kind, "navigate_to_room", execute_callback=execute)
    client_node = Node("race_client", context=rt.context)
    client = ThreadSafeActionClient(client_node, kind, "navigate_to_room")
    rt.add(server_node)
    rt.add(client_node)
    rt.start()
    try:
        assert client.wait_for_server(timeout_sec=30.0)
        client._pending_goal_requests = _SlowToRecord(threading.current_thread())
        sent = client.send_goal_async(kind.Goal(room="room1"))
        deadline = time.monotonic() + 10.0
        while not sent.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert sent.done(), "the goal's answer was dropped"
        handle = sent.result()
        assert handle.accepted
        result = handle.get_result_async()
        deadline = time.monotonic() + 10.0
        while not result.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert result.done() and result.result().result.room_id == "room1"
    finally:
        rt.shutdown()
