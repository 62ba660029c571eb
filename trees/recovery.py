"""Recoveries as an explicit subtree (like Nav2's), chosen by the failure that triggered
them: BLOCKED and DOOR_CLOSED back off the wall and turn onto the corridor axis,
TARGET_NOT_FOUND turns round to look back, TIMEOUT waits; any other failure needs none."""

from __future__ import annotations

import math

import py_trees
from py_trees.behaviours import Success as AlwaysSucceed
from py_trees.composites import Selector, Sequence

from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.recovery import BackUp, FaceCorridor, FailureIs, Spin, Wait
from pmnav_bt.failures import FailureCode

WAIT_S = 2.0


def recovery_subtree(ctx: Context, name: str = "Recovery") -> py_trees.behaviour.Behaviour:
    """The recovery the last failure calls for; SUCCESS when there is none to do."""
    back_off = Sequence(
        "BackOffWall",
        memory=True,
        children=[
            FailureIs("WasBlocked", ctx, FailureCode.BLOCKED, FailureCode.DOOR_CLOSED),
            BackUp("BackUp", ctx),
            FaceCorridor("FaceCorridor", ctx),
        ],
    )
    look_back = Sequence(
        "LookBack",
        memory=True,
        children=[
            FailureIs("WasNotFound", ctx, FailureCode.TARGET_NOT_FOUND),
            Spin("SpinToLook", ctx, math.pi),
        ],
    )
    wait = Sequence(
        "WaitItOut",
        memory=True,
        children=[FailureIs("WasTimeout", ctx, FailureCode.TIMEOUT), Wait("Wait", ctx, WAIT_S)],
    )
    return Selector(
        name, memory=True, children=[back_off, look_back, wait, AlwaysSucceed(name="NoRecovery")]
    )
