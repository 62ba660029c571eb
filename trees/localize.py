"""Active localization as an explicit subtree (issue 15).

Take the six-view panorama (and the six views between them when it read fewer than two
signs: a plate on a seam between two 60-degree views is cut in both), add it to the
corridor belief, fix the pose if the belief allows; otherwise drive along the corridor
axis towards where the map says signs are readable (``follow_lead_subtree``), and try
again::

    Localize (Retry)
      LocalizeOrExplore
        LocalizeOnce
          LocalizeLookOrNot: LookTellsNothing | Look (panorama, UpdateBelief)
          LocalizeFix
        LocalizeExplore
          LocalizeAlongCorridor
            ChooseLead, AlignWithCorridor, DriveAlongCorridor
            CornerPassed: not at a corner | SlidePastCorner, AlignWithCorridor,
                          DriveAlongCorridor
            OffTheWall: not blocked | BackUp
          TryAgain

The recoveries are ``trees.recovery``.
"""

from __future__ import annotations

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.composites import Selector, Sequence
from py_trees.decorators import Inverter, Retry

from pmnav_bt.behaviours.belief import (
    DriveEnd,
    FixFromBelief,
    LookTellsNothing,
    NoSignInReach,
    UpdateBelief,
)
from pmnav_bt.behaviours.capture import CaptureViews
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.follow_lead import (
    BACK_OFF_S,
    AlignWithCorridor,
    ChooseLead,
    DriveAlongCorridor,
    DriveEnded,
    SlidePastCorner,
)
from pmnav_bt.behaviours.localize import SignsRead, enough_doors, localization_yaws, read_signs
from pmnav_bt.behaviours.recovery import BackUp


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
            follow_lead_subtree(ctx, cfg.explore_distance, name),
            AlwaysFail(name="TryAgain"),
        ],
    )
    return Retry(
        name,
        Selector(f"{name}OrExplore", memory=True, children=[once, explore]),
        num_failures=cfg.localization_attempts,
    )


def follow_lead_subtree(
    ctx: Context, max_distance: float, name: str = "Localize"
) -> py_trees.behaviour.Behaviour:
    """The drive along the corridor towards where the belief leads (``follow_lead``):
    choose the lead, face it, drive; a corner met early in the drive is slid past, then
    the drive faces its heading again and goes on; a drive that ended blocked backs off
    the wall (``BackUp``, for at most ``BACK_OFF_S``). SUCCESS when the drive is over
    (``drive_end`` says how)."""
    slide = Sequence(
        f"{name}SlidePast",
        memory=True,
        children=[
            SlidePastCorner(f"{name}SlidePastCorner", ctx),
            AlignWithCorridor(f"{name}AlignAgain", ctx),
            DriveAlongCorridor(f"{name}DriveOn", ctx),
        ],
    )
    at_corner = DriveEnded(f"{name}AtCorner", ctx, DriveEnd.CORNER)
    blocked = DriveEnded(f"{name}Blocked", ctx, DriveEnd.BLOCKED)
    return Sequence(
        f"{name}AlongCorridor",
        memory=True,
        children=[
            ChooseLead(f"{name}ChooseLead", ctx, max_distance),
            AlignWithCorridor(f"{name}Align", ctx),
            DriveAlongCorridor(f"{name}Drive", ctx),
            Selector(
                f"{name}CornerPassed",
                memory=True,
                children=[Inverter(f"{name}NotAtCorner", at_corner), slide],
            ),
            Selector(
                f"{name}OffTheWall",
                memory=True,
                children=[
                    Inverter(f"{name}NotBlocked", blocked),
                    BackUp(f"{name}BackUp", ctx, timeout_s=BACK_OFF_S),
                ],
            ),
        ],
    )
