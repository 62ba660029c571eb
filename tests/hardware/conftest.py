"""Fixtures for the ROS 2 tests: a private DDS domain per test and the probe node.

Every ROS process of these tests, this one included, runs with
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST and a ROS_DOMAIN_ID of its own (derived
from the pid and a counter), set before rclpy starts.
"""

from __future__ import annotations

import itertools
import os

import pytest

from pmnav_bt.hardware.env import domain_id_for, rclpy_available

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

_counter = itertools.count()


def _skip_reason() -> str | None:
    ok, why = rclpy_available()
    return None if ok else f"ROS 2 (rclpy) not available: {why}"


@pytest.fixture(scope="session")
def ros_required():
    why = _skip_reason()
    if why:
        pytest.skip(why)


def _next_domain_id() -> int:
    """A ROS_DOMAIN_ID in 1..101 that no other test of this run has had (for < 101 tests)."""
    return domain_id_for(os.getpid() * 7 + next(_counter))


@pytest.fixture(scope="session")
def new_domain_id(ros_required):
    """A function giving a fresh domain id, for fixtures wider than one test."""
    return _next_domain_id


@pytest.fixture
def domain_id(ros_required) -> int:
    """A ROS_DOMAIN_ID in 1..101 for this test only."""
    d = _next_domain_id()
    os.environ["ROS_DOMAIN_ID"] = str(d)
    return d


@pytest.fixture
def probe(domain_id):
    """An in-process probe node in the test's domain, spun in the background."""
    from pmnav_bt.hardware.runtime import RosRuntime
    from pmnav_bt.hardware.testing import Probe

    rt = RosRuntime(args=[], domain_id=domain_id)
    p = Probe(rt)
    rt.start()
    try:
        yield p
    finally:
        rt.shutdown()
