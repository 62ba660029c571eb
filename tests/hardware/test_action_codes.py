"""Every failure code has its constant in the NavigateToRoom action's result (read from
the .action file: no ROS needed), each a number of its own; a code without one would
reach a ROS client as UNKNOWN."""

from __future__ import annotations

import re
from pathlib import Path

from pmnav_bt.failures import FailureCode

ACTION = Path(__file__).parents[2] / "interfaces/pmnav_interfaces/action/NavigateToRoom.action"


def test_every_failure_code_has_a_result_constant_of_its_own():
    result = ACTION.read_text().split("---")[1]
    constants = dict(re.findall(r"^uint16 ([A-Z_]+)=(\d+)$", result, flags=re.M))
    missing = [c.value for c in FailureCode if c.value not in constants]
    assert not missing, f"no result constant for {missing} in {ACTION.name}"
    assert len(set(constants.values())) == len(constants)  # no number used twice
