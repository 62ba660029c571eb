"""The lift subtree: ride one lift from the lobby of one level to the next, then find
where the robot is on the new level (issue 40)::

    RideOrRelease
      RideLift
        ToLobby                      to the lobby point, facing the doors
        Board (again while it came full, up to tree.lift_full_tries times)
          BoardOrLetGo
            BoardOnce: BoardingBegins, CallLift, WaitForLift (LIFT_NOT_COMING),
                       FindDoors (the doorway in depth puts the estimate right along the
                       wall), ToLobby again, CabinHasRoom (LIFT_FULL)
            LetItGo: it came full -> ReleaseLift, BoardAgainAllowed (the boarding's
                     actions added to the budget), SeeItLeave (its doors shut, at most
                     tree.lift_full_wait_s), CallAgain
        IntoCabin, TurnRound         drive into the cabin's middle, face the doors
        AskForLevel, RideToLevel     ask for the level, wait for the door there
        OnNewLevel                   drop the old level's estimate; the lift's word as prior
        OutOfCabin, LeaveLift        out to the lobby facing the corridor; end the session
        ArrivalLook, CheckLevel      the panorama; its signs are the level's (WRONG_LEVEL)
        FixOnLevel: weigh that panorama and fix, or the lift's word stands when the
                    belief agrees with it but cannot sharpen it | the localization subtree
      GiveUpLift                     any failure: end the session, keep the failure

The leaves before the ride work on the level left (``ctx_from``: its map and grounder),
those after it on the level reached (``ctx_to``). Timeouts are clock seconds of the tree's
``Clock`` (``tree.lift_wait_s`` for the lift to come, ``tree.lift_ride_s`` for the ride).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import py_trees
from py_trees.behaviours import Failure as AlwaysFail
from py_trees.common import Access
from py_trees.composites import Selector

from pmnav_bt.backends import Backends
from pmnav_bt.behaviours.belief import FixFromBelief, UpdateBelief
from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.decorators import RetryWhile
from pmnav_bt.behaviours.lift import (
    BoardAgainAllowed,
    BoardingBegins,
    CabinHasRoom,
    CallLift,
    CheckLevel,
    DriveThrough,
    FindDoors,
    LiftWordStands,
    OnNewLevel,
    ReleaseLift,
    Ride,
    SeeItLeave,
    ToLobby,
    WaitForLift,
    into_cabin,
)
from pmnav_bt.behaviours.recovery import FailureIs, Spin
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.building import Building
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.seams import Lift
from pmnav_bt.trees.localize import active_localize_subtree, panorama_subtree
from pmnav_bt.trees.map_watch import watch_misreads
from pmnav_bt.trees.mission import sequence
from pmnav_bt.trees.runner import make_context


def lift_subtree(
    ctx_from: Context,
    ctx_to: Context,
    lift: Lift,
    ride: Ride,
    levels: Mapping[str, Building],
    name: str = "Lift",
) -> py_trees.behaviour.Behaviour:
    """Ride ``ride`` on ``lift`` and re-localize on its far level (see the module);
    ``levels``: every level's building, by level name, to tell their signs apart."""
    cfg = ctx_from.config.tree
    board_once = sequence(
        f"{name}BoardOnce",
        BoardingBegins(f"{name}BoardingBegins", ctx_from),
        CallLift(f"{name}Call", ctx_from, lift, ride, ride.from_level),
        WaitForLift(f"{name}WaitForDoor", ctx_from, lift, ride, ride.from_level, cfg.lift_wait_s),
        FindDoors(f"{name}FindDoors", ctx_from, ride),
        ToLobby(f"{name}BeforeDoors", ctx_from, ride),
        CabinHasRoom(f"{name}CabinHasRoom", ctx_from, ride, cfg.lift_full_tries),
    )
    let_go = sequence(
        f"{name}LetItGo",
        FailureIs(f"{name}CameFull", ctx_from, FailureCode.LIFT_FULL),
        ReleaseLift(f"{name}LetItGoOn", ctx_from, lift, ride),
        BoardAgainAllowed(f"{name}BoardAgainAllowed", ctx_from),
        SeeItLeave(f"{name}SeeItLeave", ctx_from, lift, ride, cfg.lift_full_wait_s),
        AlwaysFail(name=f"{name}CallAgain"),
    )
    bb = py_trees.blackboard.Client(name=f"{name}Board", namespace=NAMESPACE)
    bb.register_key(key="failure", access=Access.READ)
    bb.register_key(key="lift_full_seen", access=Access.READ)

    def full_again() -> bool:
        failure = bb.get("failure") if bb.exists("failure") else None
        seen = (bb.get("lift_full_seen") if bb.exists("lift_full_seen") else 0) or 0
        return failure is not None and failure.code == FailureCode.LIFT_FULL and (
            seen < cfg.lift_full_tries
        )

    board = RetryWhile(
        f"{name}Board",
        Selector(f"{name}BoardOrLetGo", memory=True, children=[board_once, let_go]),
        full_again,
    )
    fix_here = Selector(
        f"{name}FixOnLevel",
        memory=True,
        children=[
            sequence(
                f"{name}FixFromArrival",
                UpdateBelief(f"{name}ArrivalBelief", ctx_to, anchored=True),
                Selector(
                    f"{name}FixOrWordStands",
                    memory=True,
                    children=[
                        FixFromBelief(f"{name}ArrivalFix", ctx_to),
                        LiftWordStands(f"{name}WordStands", ctx_to),
                    ],
                ),
            ),
            active_localize_subtree(ctx_to, f"{name}Localize"),
        ],
    )
    ride_it = sequence(
        f"{name}Ride",
        ToLobby(f"{name}ToLobby", ctx_from, ride),
        board,
        DriveThrough(
            f"{name}IntoCabin", ctx_from, ride, into_cabin(ride.board), "into", way=True
        ),
        Spin(f"{name}TurnRound", ctx_from, math.pi),
        CallLift(f"{name}AskForLevel", ctx_from, lift, ride, ride.to_level),
        WaitForLift(f"{name}RideToLevel", ctx_from, lift, ride, ride.to_level, cfg.lift_ride_s),
        OnNewLevel(f"{name}OnNewLevel", ctx_to, ride),
        DriveThrough(f"{name}OutOfCabin", ctx_to, ride, into_cabin(ride.alight), "out of"),
        ReleaseLift(f"{name}LeaveLift", ctx_to, lift, ride),
        panorama_subtree(ctx_to, f"{name}Arrival"),
        CheckLevel(f"{name}CheckLevel", ctx_to, ride, levels),
        fix_here,
    )
    return Selector(
        f"{name}OrRelease",
        memory=True,
        children=[
            ride_it,
            sequence(
                f"{name}GiveUp",
                ReleaseLift(f"{name}GiveUpLift", ctx_from, lift, ride),
                AlwaysFail(name=f"{name}Failed"),
            ),
        ],
    )


def level_context(
    ctx: Context,
    pm: PrioriMap,
    seed: int = 0,
    *,
    on_robot: bool = False,
    backends: Backends | None = None,
    grid=None,
) -> Context:
    """``ctx`` on another level: the same body, worker, trace, odometer, budget and map
    updates; that level's map, back ends (the grounder reads that level's signs), detour
    check and walls (``make_context``'s wiring: ``backends``, ``grid`` as there)."""
    level = make_context(
        ctx.base, pm, ctx.config, seed, ctx.budget_actions, on_robot=on_robot, backends=backends,
        grid=grid,
    )  # fmt: skip
    level.worker.shutdown()
    level = dataclasses.replace(
        level, worker=ctx.worker, trace=ctx.trace, odometer=ctx.odometer,
        map_updates=ctx.map_updates, misreads=None,
    )  # fmt: skip
    watch_misreads(level)
    return level
