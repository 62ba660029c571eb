"""Active localization and recoveries as explicit subtrees (issue 15).

Localization: take the six-view panorama (and the six views between them when it read
fewer than two signs: a plate on a seam between two 60-degree views is cut in both), add
it to the corridor belief, fix the pose if the belief allows; otherwise drive along the
corridor axis towards where the map says signs are readable, and try again. Recoveries
(like Nav2's) are chosen by the failure that triggered them: BLOCKED backs off the wall
and turns onto the corridor axis, TARGET_NOT_FOUND turns round to look back, TIMEOUT
waits.
"""

from __future__ import annotations

import math

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.behaviours import Success as AlwaysSucceed
from py_trees.composites import Selector, Sequence
from py_trees.decorators import Retry

from pmnav_bt.behaviours.active_localize import (
    FixFromBelief,
    FollowLead,
    LookTellsNothing,
    NoSignInReach,
    UpdateBelief,
)
from pmnav_bt.behaviours.capture import CaptureViews
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.localize import SignsRead, enough_doors, localization_yaws, read_signs
from pmnav_bt.behaviours.recovery import BackUp, FaceCorridor, FailureIs, Spin, Wait
from pmnav_bt.failures import FailureCode

WAIT_S = 2.0


def panorama_subtree(ctx: Context, name: str = "Localize") -> py_trees.behaviour.Behaviour:
    """The localization panorama: six views 60 deg apart, stopping once three doors are
    read; when they read fewer than two signs, the six views half-way between them too
    (taken on from the last view: the same relative yaws fall between the first six), as a
    plate on a seam between two 60-degree views is cut in both, unless the belief so far
    says no sign is in reach here (a bare stretch: the turn would read nothing). Writes
    ``views``."""
    return Sequence(
        f"{name}Panorama",
        memory=True,
        children=[
            CaptureViews(f"{name}Views", ctx, localization_yaws, read_signs, enough=enough_doors),
            Selector(
                f"{name}ViewsEnough",
                memory=True,
                children=[
                    SignsRead(f"{name}TwoSignsRead", ctx, n=2),
                    NoSignInReach(f"{name}NoSignInReach", ctx),
                    CaptureViews(
                        f"{name}ViewsBetween",
                        ctx,
                        localization_yaws,
                        read_signs,
                        enough=enough_doors,
                        sweep=False,
                        extend=True,
                    ),
                ],
            ),
        ],
    )


def active_localize_subtree(ctx: Context, name: str = "Localize") -> py_trees.behaviour.Behaviour:
    """Panorama -> belief -> fix; else drive along the corridor towards signs, and retry.
    After a drive, the panorama is skipped where it cannot tell the belief's likely places
    apart (``LookTellsNothing``)."""
    cfg = ctx.config.tree
    look = Selector(
        f"{name}LookOrNot",
        memory=True,
        children=[
            LookTellsNothing(f"{name}LookTellsNothing", ctx),
            Sequence(
                f"{name}Look",
                memory=True,
                children=[panorama_subtree(ctx, name), UpdateBelief(f"{name}Belief", ctx)],
            ),
        ],
    )
    once = Sequence(f"{name}Once", memory=True, children=[look, FixFromBelief(f"{name}Fix", ctx)])
    explore = Sequence(
        f"{name}Explore",
        memory=True,
        children=[
            FollowLead(f"{name}AlongCorridor", ctx, cfg.explore_distance),
            AlwaysFail(name="TryAgain"),
        ],
    )
    return Retry(
        name,
        Selector(f"{name}OrExplore", memory=True, children=[once, explore]),
        num_failures=cfg.localization_attempts,
    )


def recovery_subtree(ctx: Context, name: str = "Recovery") -> py_trees.behaviour.Behaviour:
    """The recovery the last failure calls for; SUCCESS when there is none to do."""
    back_off = Sequence(
        "BackOffWall",
        memory=True,
        children=[
            FailureIs("WasBlocked", ctx, FailureCode.BLOCKED),
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
