"""The PM-Nav tree: localize, plan, then per step "target determination -> search ->
verification -> target update", with re-search, replanning and a budget.

Two tree variants (paper, Table 4; registered in ``pmnav_bt/tree_variants.py``): ``pmnav``
(``build_pmnav_tree``) refines the coarse direction with grounding and the refiner back
end (``refiner.backend``; a refiner that ``drives_approach``, a pixel-goal policy such as
``pixelnav``, also drives the approach to the goal door in closed loop); ``coarse_only``
(``build_coarse_only_tree``) keeps the coarse view direction and uses no refiner at all.
"""

from __future__ import annotations

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.composites import Selector
from py_trees.decorators import FailureIsSuccess, Repeat, Retry

from pmnav_bt.behaviours.capture import CaptureViews, nearest_first, search_centre, search_yaws
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.decorators import ClockTimeout
from pmnav_bt.behaviours.hidden_sign import LOOK_AGAIN_AFTER_S, SignHidden
from pmnav_bt.behaviours.motion import (
    Approach,
    Arrive,
    CheckOpening,
    DriveToWaypoint,
    MoveToward,
    TurnOnto,
)
from pmnav_bt.behaviours.planning import (
    CheckGoal,
    DetermineTarget,
    MakePlan,
    NoteFailure,
    PlanComplete,
    TargetIs,
    UpdateTarget,
)
from pmnav_bt.behaviours.policy_approach import PolicyApproach
from pmnav_bt.behaviours.pose import CorrectHeading, SnapToCorridor
from pmnav_bt.behaviours.recovery import Wait
from pmnav_bt.behaviours.search import (
    CoarseDirection,
    FineDirection,
    Ground,
    Verify,
    target_bearing,
    target_entity,
)
from pmnav_bt.perception.read_range import SearchRanges
from pmnav_bt.trees.active_read import read_closer_subtree
from pmnav_bt.trees.localize import active_localize_subtree
from pmnav_bt.trees.mission import monitored_mission, sequence
from pmnav_bt.trees.recovery import recovery_subtree


def localize_subtree(ctx: Context, name: str = "Localize") -> py_trees.behaviour.Behaviour:
    """Capture the six localization views, add them to the corridor belief and fix the
    pose; with too few landmarks, drive along the corridor towards signs and retry."""
    return active_localize_subtree(ctx, name)


def search_views(b: py_trees.behaviour.Behaviour) -> list[float]:
    """The search views (rad from the heading): the paper's, centred on the target when the
    map puts it aside, taken nearest its bearing first."""
    bearing = target_bearing(b)
    return nearest_first(search_yaws(b.get("last_action"), search_centre(bearing)), bearing)


def step_subtree(ctx: Context, refine: bool = True) -> py_trees.behaviour.Behaviour:
    """One plan step: target determination, then search-verify-approach for a visible
    target or drive-turn-check for an unseen turn or fork, then target update.
    ``refine=False``: coarse-only (no grounding, no refiner, the map approach)."""
    cfg = ctx.config.tree
    # how close to go to read the target's sign: the reader's range for its plate kind
    # (perception/read_range.py), unless set in the config
    ranges = SearchRanges(ctx.config, ctx.pm.building)

    def search_range(b) -> float:
        t = b.get("target")
        return ranges.search_range_to(target_entity(b), t.position, t.target, t.heading)

    def research_distance(b) -> float:
        return ranges.of(target_entity(b)).research_distance

    # A refiner that drives the approach (a pixel-goal policy, refiner.backend=pixelnav)
    # does so in closed loop.
    closed_loop = refine and ctx.refiner.drives_approach
    search_once = sequence(
        "SearchOnce",
        CaptureViews(
            "SearchViews",
            ctx,
            search_views,
            target_entity,
            enough=lambda views: any(d.score >= 0.5 for d in views[-1].detections or ()),
            sweep=False,
        ),
        CoarseDirection("CoarseDirection", ctx),
        # coarse-only (Table 4): no grounding and no refinement of the view direction
        *([Ground("Grounding", ctx)] if refine else []),
        FineDirection("FineDirection", ctx, refine=refine),
        Verify("Verification", ctx),
        CorrectHeading("HeadingFromWalls", ctx),
    )
    research = sequence(
        "MoveOnAndResearch",
        Selector(
            "WaitOrMoveOn",
            memory=True,
            children=[
                # A sign hidden behind someone is looked for again after a moment, from
                # here: it was hidden, not absent.
                sequence(
                    "LookAgainLater",
                    SignHidden("SignHidden", ctx),
                    Wait("WaitForTheView", ctx, LOOK_AGAIN_AFTER_S),
                ),
                # On up to level with the target (its node): a sign hangs beside its
                # door, maybe on the far side, readable (not just visible) only from
                # about there.
                MoveToward("MoveOn", ctx, keep=0.0, distance=research_distance),
            ],
        ),
        AlwaysFail(name="SearchAgain"),
    )
    # A plate seen near the target but not read is read from nearer (grounding a fresh
    # frame there: not in the coarse-only ablation, which grounds nothing).
    read = [read_closer_subtree(ctx)] if refine and cfg.active_reads > 0 else []
    visible = sequence(
        "SeenTarget",
        TargetIs("IsVisible", ctx, visible=True),
        MoveToward("IntoSearchRange", ctx, keep=search_range),
        Retry(
            "Search",
            Selector("SearchOrMoveOn", memory=True, children=[search_once, *read, research]),
            num_failures=cfg.search_attempts,
        ),
        (PolicyApproach if closed_loop else Approach)("Approach", ctx),
    )
    unseen = sequence(
        "UnseenWaypoint",
        TargetIs("IsUnseen", ctx, visible=False),
        DriveToWaypoint("CornerCheck", ctx),
        TurnOnto("TurnOnto", ctx),
        CheckOpening("ForkChoice", ctx),
    )
    step = sequence(
        "Step",
        DetermineTarget("TargetDetermination", ctx),
        Selector("ByTargetKind", memory=True, children=[visible, unseen]),
        UpdateTarget("TargetUpdate", ctx),
    )
    return ClockTimeout("StepTimeout", step, ctx.now, cfg.step_timeout_s)


def build_pmnav_tree(ctx: Context, goal: str) -> py_trees.trees.BehaviourTree:
    """The whole PM-Nav tree for ``goal`` (tree variant ``pmnav``)."""
    return _pmnav_tree(ctx, goal, refine=True)


def build_coarse_only_tree(ctx: Context, goal: str) -> py_trees.trees.BehaviourTree:
    """PM-Nav without grounding or refinement of the view direction, for ``goal`` (tree
    variant ``coarse_only``, paper Table 4)."""
    return _pmnav_tree(ctx, goal, refine=False)


def _pmnav_tree(ctx: Context, goal: str, refine: bool) -> py_trees.trees.BehaviourTree:
    mission = sequence(
        "Mission",
        CheckGoal("CheckGoal", ctx),
        localize_subtree(ctx),
        navigate_subtree(ctx, refine),
        Arrive("Arrive", ctx),
    )
    return monitored_mission(ctx, "PM-Nav", mission, goal)


def navigate_subtree(
    ctx: Context, refine: bool = True, name: str = "Navigate"
) -> py_trees.behaviour.Behaviour:
    """Plan from the estimate and follow the plan step by step, recovering and replanning
    (``tree.replans`` times) by the failure code: the tree between localizing and
    arriving (a leg of a mission across levels, ``trees/site.py``, too)."""
    cfg = ctx.config.tree
    follow = Selector(
        "FollowPlan",
        memory=False,
        children=[
            PlanComplete("PlanComplete", ctx),
            Repeat("EachStep", step_subtree(ctx, refine), num_success=-1),
        ],
    )
    recover = sequence(
        "Recover",
        NoteFailure("NoteFailure", ctx),
        recovery_subtree(ctx),
        FailureIsSuccess("TryRelocalize", localize_subtree(ctx, "Relocalize")),
        AlwaysFail(name="Replan"),
    )
    return Retry(
        name,
        Selector(
            "PlanOrRecover",
            memory=True,
            children=[
                sequence(
                    "PlanAndFollow",
                    SnapToCorridor("SnapToCorridor", ctx),
                    MakePlan("Plan", ctx),
                    follow,
                ),
                recover,
            ],
        ),
        num_failures=cfg.replans + 1,
    )
