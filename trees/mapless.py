"""The map-less baseline: the same body and perception as PM-Nav, no priori-map, no plan.

The analogue of the paper's SG-Nav / InstructNav rows (Table 1: zero-shot navigators
without a prior map) in functional buildings. It explores frontier-style on what depth
shows (its own occupancy grid in the odometry frame: corridors seen, branches not yet
looked down, where it has been), reads signs as it looks around and as it drives, and
once the goal room's sign and door are seen it places the door by the refiner's range
and approaches it with PM-Nav's drive and stop. It knows the building's sign vocabulary
(which sign names which room: ``map.signs_only.SignsOnly``) and nothing of where: it is
registered so in ``pmnav_bt/tree_variants.py`` (``SIGN_VOCABULARY``), which builds its context with
no planner, and drives round an obstacle where depth shows the floor free (no walls known).

    Mission
      StartExploring                       goal -> goal_entity, an empty grid
      Explore (again while frontiers last)
        SeenOrExplore
          LookAround: Panorama (6 views, reading the goal's sign) -> RecordViews -> ChooseView
          MoveOn: ExploreFrontier (stops when the sign shows) -> LookAgain (fail: loop)
      ToTheDoor: Grounding -> PlaceDoor -> ApproachNear -> LookAtDoor -> PlaceAgain
                 -> Approach -> Arrive
    Monitor (action budget, body faults) in parallel
"""

from __future__ import annotations

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.common import Access
from py_trees.composites import Selector

from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.decorators import RetryWhile
from pmnav_bt.behaviours.explore import (
    ApproachDoor,
    ChooseView,
    ExploreFrontier,
    LookAtDoor,
    Panorama,
    PlaceDoor,
    RecordViews,
    StartExploring,
)
from pmnav_bt.behaviours.motion import Arrive
from pmnav_bt.behaviours.search import Ground
from pmnav_bt.map.signs_only import SignsOnly
from pmnav_bt.trees.mission import monitored_mission, sequence

NEAR_M = 2.0  # the door is looked at again from this far before the final approach


def build_mapless_tree(ctx: Context, goal: str) -> py_trees.trees.BehaviourTree:
    """The map-less baseline's tree for ``goal`` (a room as a person names it)."""
    if not isinstance(ctx.pm, SignsOnly):
        raise ValueError(
            "the map-less tree runs on a map-free context (trees.runner.make_context with "
            "tree.variant mapless)"
        )
    over = py_trees.blackboard.Client(name="ExploreLoop", namespace=NAMESPACE)
    over.register_key(key="explore_over", access=Access.READ)
    look = sequence(
        "LookAround",
        Panorama("Panorama", ctx),
        RecordViews("RecordViews", ctx),
        ChooseView("ChooseView", ctx),
    )
    move_on = sequence(
        "MoveOn", ExploreFrontier("ExploreFrontier", ctx), AlwaysFail(name="LookAgain")
    )
    explore = RetryWhile(
        "Explore",
        Selector("SeenOrExplore", memory=True, children=[look, move_on]),
        again=lambda: not (over.exists("explore_over") and over.explore_over),
    )
    to_door = sequence(
        "ToTheDoor",
        Ground("Grounding", ctx),
        PlaceDoor("PlaceDoor", ctx),
        ApproachDoor("ApproachNear", ctx, keep=NEAR_M),
        LookAtDoor("LookAtDoor", ctx),
        PlaceDoor("PlaceAgain", ctx),
        ApproachDoor("Approach", ctx),
        Arrive("Arrive", ctx),
    )
    mission = sequence("Mission", StartExploring("StartExploring", ctx), explore, to_door)
    return monitored_mission(ctx, "Map-less", mission, goal)
