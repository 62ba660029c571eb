"""The PM-Nav tree: localize, plan, then per step "target determination -> search ->
verification -> target update", with re-search, replanning and a budget.

Variants (paper, Table 4; ``tree.variant``): ``pmnav`` refines the coarse direction with
grounding and the refiner back end (``refiner.backend``; a pixel-goal policy such as
``pixelnav`` also drives the approach to the goal door in closed loop); ``coarse_only`` keeps
the coarse view direction and uses no refiner at all.
"""

from __future__ import annotations

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.composites import Parallel, Selector, Sequence
from py_trees.decorators import FailureIsSuccess, Repeat, Retry

from pmnav_bt.behaviours.capture import CaptureViews, nearest_first, search_centre, search_yaws
from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.decorators import ClockTimeout
from pmnav_bt.behaviours.monitor import Monitor
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
from pmnav_bt.behaviours.search import (
    CoarseDirection,
    FineDirection,
    Ground,
    Verify,
    target_bearing,
    target_entity,
)
from pmnav_bt.perception.read_range import SearchRanges
from pmnav_bt.seams import PixelGoalPolicy
from pmnav_bt.trees.localize import active_localize_subtree
from pmnav_bt.trees.recovery import recovery_subtree

VARIANTS = ("pmnav", "coarse_only")


def localize_subtree(ctx: Context, name: str = "Localize") -> py_trees.behaviour.Behaviour:
    """Capture the six localization views, add them to the corridor belief and fix the
    pose; with too few landmarks, drive along the corridor towards signs and retry."""
    return active_localize_subtree(ctx, name)


def search_views(b: py_trees.behaviour.Behaviour) -> list[float]:
    """The search views (rad from the heading): the paper's, centred on the target when the
    map puts it aside, taken nearest its bearing first."""
    bearing = target_bearing(b)
    return nearest_first(search_yaws(b.get("last_action"), search_centre(bearing)), bearing)


def step_subtree(ctx: Context) -> py_trees.behaviour.Behaviour:
    """One plan step: target determination, then search-verify-approach for a visible
    target or drive-turn-check for an unseen turn or fork, then target update."""
    cfg = ctx.config.tree
    # how close to go to read the target's sign: the reader's range for its plate kind
    # (perception/read_range.py), unless set in the config
    ranges = SearchRanges(ctx.config, ctx.pm.building)

    def search_range(b) -> float:
        t = b.get("target")
        return ranges.search_range_to(target_entity(b), t.position, t.target, t.heading)

    def research_distance(b) -> float:
        return ranges.of(target_entity(b)).research_distance

    coarse_only = cfg.variant == "coarse_only"
    # A pixel-goal policy (refiner.backend=pixelnav) drives the approach in closed loop.
    closed_loop = not coarse_only and isinstance(ctx.refiner, PixelGoalPolicy)
    search_once = Sequence(
        "SearchOnce",
        memory=True,
        children=[
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
            *([] if coarse_only else [Ground("Grounding", ctx)]),
            FineDirection("FineDirection", ctx, refine=not coarse_only),
            Verify("Verification", ctx),
            CorrectHeading("HeadingFromWalls", ctx),
        ],
    )
    research = Sequence(
        "MoveOnAndResearch",
        memory=True,
        children=[
            # On up to level with the target (its node): a sign hangs beside its door,
            # maybe on the far side, readable (not just visible) only from about there.
            MoveToward("MoveOn", ctx, keep=0.0, distance=research_distance),
            AlwaysFail(name="SearchAgain"),
        ],
    )
    visible = Sequence(
        "SeenTarget",
        memory=True,
        children=[
            TargetIs("IsVisible", ctx, visible=True),
            MoveToward("IntoSearchRange", ctx, keep=search_range),
            Retry(
                "Search",
                Selector("SearchOrMoveOn", memory=True, children=[search_once, research]),
                num_failures=cfg.search_attempts,
            ),
            (PolicyApproach if closed_loop else Approach)("Approach", ctx),
        ],
    )
    unseen = Sequence(
        "UnseenWaypoint",
        memory=True,
        children=[
            TargetIs("IsUnseen", ctx, visible=False),
            DriveToWaypoint("CornerCheck", ctx),
            TurnOnto("TurnOnto", ctx),
            CheckOpening("ForkChoice", ctx),
        ],
    )
    step = Sequence(
        "Step",
        memory=True,
        children=[
            DetermineTarget("TargetDetermination", ctx),
            Selector("ByTargetKind", memory=True, children=[visible, unseen]),
            UpdateTarget("TargetUpdate", ctx),
        ],
    )
    return ClockTimeout("StepTimeout", step, ctx.now, cfg.step_timeout_s)


def build_pmnav_tree(ctx: Context, goal: str) -> py_trees.trees.BehaviourTree:
    """The whole PM-Nav tree for ``goal``, for the variant named in ``ctx.config.tree``."""
    cfg = ctx.config.tree
    if cfg.variant not in VARIANTS:
        raise ValueError(f"unknown tree variant {cfg.variant!r}; choose from {VARIANTS}")
    follow = Selector(
        "FollowPlan",
        memory=False,
        children=[
            PlanComplete("PlanComplete", ctx),
            Repeat("EachStep", step_subtree(ctx), num_success=-1),
        ],
    )
    recover = Sequence(
        "Recover",
        memory=True,
        children=[
            NoteFailure("NoteFailure", ctx),
            recovery_subtree(ctx),
            FailureIsSuccess("TryRelocalize", localize_subtree(ctx, "Relocalize")),
            AlwaysFail(name="Replan"),
        ],
    )
    navigate = Retry(
        "Navigate",
        Selector(
            "PlanOrRecover",
            memory=True,
            children=[
                Sequence(
                    "PlanAndFollow",
                    memory=True,
                    children=[SnapToCorridor("SnapToCorridor", ctx), MakePlan("Plan", ctx), follow],
                ),
                recover,
            ],
        ),
        num_failures=cfg.replans + 1,
    )
    mission = Sequence(
        "Mission",
        memory=True,
        children=[
            CheckGoal("CheckGoal", ctx),
            localize_subtree(ctx),
            navigate,
            Arrive("Arrive", ctx),
        ],
    )
    root = Parallel(
        "PM-Nav",
        policy=py_trees.common.ParallelPolicy.SuccessOnOne(),
        children=[Monitor("Monitor", ctx), mission],
    )
    bb = py_trees.blackboard.Client(name="setup", namespace=NAMESPACE)
    bb.register_key(key="goal", access=py_trees.common.Access.WRITE)
    bb.goal = goal
    return py_trees.trees.BehaviourTree(root)
