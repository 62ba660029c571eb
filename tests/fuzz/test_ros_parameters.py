"""``pmnav-ros`` with bad parameters: one line, non-zero, before the node does any work.

The building and the overrides go through the same loaders as the CLI; numbers are
checked against hardware/param_limits.py. Skipped where rclpy is not installed.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from fuzzkit import TRIED, assert_clean_failure

from pmnav_bt.hardware.env import domain_id_for, rclpy_available, ros_env

pytestmark = [
    pytest.mark.skipif(not rclpy_available()[0], reason="ROS 2 (rclpy) not installed"),
    pytest.mark.timeout(120),
]


@pytest.mark.parametrize(
    "param, words",
    [
        ("building:={deep}", ["deep.yaml", "nested deeper than 32 levels"]),
        ("overrides:=tree.tick_hz=[", ["parameter 'overrides'", "not valid YAML"]),
        ("viz_hz:=.inf", ["parameter 'viz_hz'", "finite"]),
    ],
    ids=["deep-building", "overrides-not-yaml", "viz-hz-inf"],
)
def test_bad_parameters(tmp_path, param, words):
    TRIED["pmnav-ros: bad parameters"] += 1
    deep = tmp_path / "deep.yaml"
    deep.write_text("schema_version: 1\nwaypoints: " + "[" * 50_000 + "]" * 50_000)
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "pmnav_bt.hardware.node",
            "--ros-args",
            "-p",
            param.format(deep=deep),
        ],
        env=ros_env(domain_id=domain_id_for(os.getpid() + len(param))),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert_clean_failure(res, *words)
