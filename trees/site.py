"""The mission across levels (issue 40): the PM-Nav tree on each level, a lift ride
between levels::

    PM-Nav across levels (beside the Monitor)
      Mission
        StartLevel                the blackboard's level: the start level
        Localize                  on the start level
        Leg1                      navigate_subtree to the first ride's lift lobby
        Lift1                     lift_subtree: ride, re-localize on the next level
        Leg2 ...                  to the next lobby, or to the goal room on the last level
        Arrive

The route across levels (which lifts, how many rides: a ``SitePlan`` of
``planning/site_plan.py``) is fixed when the tree is built, from the start the task
gives; on each level the leg plans from the tree's own estimate as the one-level tree
does (``MakePlan``), to the lift's landmark (``LobbyPlanner``) or, on the last level, to
the goal room. Each level has its own ``Context`` (``level_context``: its map, and a
grounder that reads its signs); the body, clock, worker, trace and budget are shared.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import py_trees

from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.lift import Ride, StartLevel
from pmnav_bt.behaviours.motion import Arrive
from pmnav_bt.map.lift_doorway import doorway
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.leg_planner import LobbyPlanner
from pmnav_bt.planning.site_plan import SitePlan
from pmnav_bt.seams import Lift
from pmnav_bt.trees.lift import lift_subtree
from pmnav_bt.trees.mission import monitored_mission, sequence
from pmnav_bt.trees.pmnav import localize_subtree, navigate_subtree

SESSION = "pmnav"  # the simulator's lift session (one robot); a ROS node asks by its name


def site_rides(sm: SiteMap, plan: SitePlan, session: str = SESSION) -> list[Ride]:
    """The rides of ``plan``, each with its lift's doorway on both levels' maps."""
    rides = []
    for r in plan.rides:
        link = sm.site.lift(r.lift)
        a, b = link.lobbies[r.from_level], link.lobbies[r.to_level]
        rides.append(
            Ride(
                r.lift, link.display_name, r.from_level, r.to_level,
                doorway(sm.maps[r.from_level], a), doorway(sm.maps[r.to_level], b), session,
            )
        )  # fmt: skip
    return rides


def build_site_tree(
    contexts: Mapping[str, Context],
    sm: SiteMap,
    plan: SitePlan,
    lift: Lift,
    refine: bool = True,
    session: str = SESSION,
) -> py_trees.trees.BehaviourTree:
    """The mission of ``plan`` (see the module); ``contexts``: each level's Context by
    level name (``level_context``), ``lift``: the building's lift system, ``session``: the
    name the robot asks for lifts by (unique among the lift system's requesters: Open-RMF
    lifts serve one session at a time)."""
    rides = site_rides(sm, plan, session)
    levels = {lv.name: lv.building for lv in sm.site.levels}
    first = contexts[plan.start_level]
    parts: list[py_trees.behaviour.Behaviour] = [
        StartLevel("StartLevel", first, plan.start_level),
        localize_subtree(first),
    ]
    for i, leg in enumerate(plan.legs):
        ctx = contexts[leg.level]
        if i < len(rides):  # to the lobby of the next ride
            lobby = sm.site.lift(rides[i].lift).lobbies[leg.level]
            ctx = dataclasses.replace(ctx, planner=LobbyPlanner(lobby))
        parts.append(navigate_subtree(ctx, refine, f"Leg{i + 1}"))
        if i < len(rides):
            nxt = contexts[rides[i].to_level]
            parts.append(lift_subtree(ctx, nxt, lift, rides[i], levels, f"Lift{i + 1}"))
    last = contexts[plan.goal_level]
    parts.append(Arrive("Arrive", last))
    mission = sequence("Mission", *parts)
    return monitored_mission(first, "PM-Nav across levels", mission, plan.goal)
