"""The active read: a plate seen but not read near the target is read from where it can be
(``behaviours/active_read.py``): plan a reading pose, drive there, read again, and take the
sighting as a search does (fine direction, verification, heading from the walls)."""

from __future__ import annotations

import py_trees

from pmnav_bt.behaviours.active_read import DriveToReadingPose, PlanReadingPose, ReadAgain
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.pose import CorrectHeading
from pmnav_bt.behaviours.search import FineDirection, Verify
from pmnav_bt.trees.mission import sequence


def read_closer_subtree(ctx: Context) -> py_trees.behaviour.Behaviour:
    """SUCCESS with the target verified from where its unread plate reads; FAILURE when
    there is no such plate, no free spot to read it from, or it is still not read."""
    return sequence(
        "ReadCloser",
        PlanReadingPose("UnreadPlate", ctx),
        DriveToReadingPose("GoWhereItReads", ctx),
        ReadAgain("ReadAgain", ctx),
        FineDirection("FineDirectionAfterReading", ctx),
        Verify("VerificationAfterReading", ctx),
        CorrectHeading("HeadingFromWallsAfterReading", ctx),
    )
