"""The Create 3's backup limit as BackupBuffer keeps it (no ROS needed)."""

from __future__ import annotations

import pytest

from pmnav_bt.backup_limit import BACKUP_LIMIT_M, BackupBuffer
from pmnav_bt.seams import Pose2D


def test_no_reverse_before_driving_forward():
    b = BackupBuffer()
    b.update(Pose2D(0.0, 0.0, 0.0))
    assert b.allows(0.2) and not b.allows(-0.1)


def test_forward_travel_fills_the_buffer_up_to_the_limit_and_reversing_empties_it():
    b = BackupBuffer()
    for x in (0.0, 0.05, 0.1, 0.4):  # 0.4 m forward along +x
        b.update(Pose2D(x, 0.0, 0.0))
    assert b.left == pytest.approx(BACKUP_LIMIT_M) and b.allows(-0.1)
    b.update(Pose2D(0.3, 0.0, 0.0))  # 0.1 m back
    assert b.left == pytest.approx(BACKUP_LIMIT_M - 0.1) and b.allows(-0.1)
    b.update(Pose2D(0.2, 0.0, 0.0))  # past the limit
    assert not b.allows(-0.1)


def test_turning_in_place_does_not_fill_it_and_a_kidnap_empties_it():
    b = BackupBuffer()
    b.update(Pose2D(0.0, 0.0, 0.0))
    b.update(Pose2D(0.0, 0.0, 1.5))
    assert not b.allows(-0.1)
    b.update(Pose2D(0.2 * 0.0707, 0.2 * 0.9975, 1.5))  # forward along the new heading
    assert b.allows(-0.1)
    b.reset()
    assert not b.allows(-0.1)
