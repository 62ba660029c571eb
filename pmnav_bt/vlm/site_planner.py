"""The VLM planner across levels: one conversation plans every level and the rides between.

A goal on the start level is the ``vlm`` planner's plan on that level, as for a building.
A goal on another level gets the H-CoT prompt across levels (``prompts/h_cot_levels.txt``):
the site's levels and lifts, then the priori-map of each level the route may pass (the
start's, the goal's and those between on the graph planner's way), with their images, and
three steps per level: which lifts join the levels; on each level the key waypoints to the
next lift's lobby (or the goal); on each level the first-person action at each landmark,
the ride step ``{lift1: take the lift to level L2}`` between two levels.

The answer is one list of steps. ``check_site_plan`` cuts it at its ride steps and checks
each level's part with the one-level validator (``validate.check_plan``) against that
level's map: from the start (or the lobby the robot leaves the lift at) to the ride's
lift's lobby, or to the goal; each ride must name a lift of the site with a lobby on the
level the robot is on and on the level it names. Problems are re-prompted as on one level;
no valid answer falls back to the graph planner across levels (``SitePlanner``), so the
tree never runs an invalid plan.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, replace

import numpy as np

from pmnav_bt.errors import PmNavError, VlmError
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.graph_planner import build_plan
from pmnav_bt.planning.resolve import StartPoint, resolve_site_room
from pmnav_bt.planning.site_plan import Leg, LiftRide, SitePlan, SitePlanner, out_of_lift
from pmnav_bt.seams import PlanConstraints, Pose2D
from pmnav_bt.vlm.client import user_message
from pmnav_bt.vlm.parse import ParseFailure, RawStep, parse_plan
from pmnav_bt.vlm.planner import PlanStats, VlmPlanner, start_point
from pmnav_bt.vlm.prompts import (
    environment_section,
    map_image,
    repair_text,
    start_description,
    template,
)
from pmnav_bt.vlm.validate import NO_CONSTRAINTS, CheckedRoute, IssueKind, PlanIssue, check_plan

log = logging.getLogger(__name__)

SITE_INPUTS = ("h-pm", "h-em")  # across levels the prompt is H-CoT; the map is the choice
_RIDE = re.compile(r"(?i)\s*(?:take|ride|use)\b.*?\blevel\s+(\S+?)\s*\.?\s*")


@dataclass(frozen=True)
class CheckedLeg:
    """One level's part of a valid answer: the level, where it starts, its goal (a lobby or
    the goal room) and its route."""

    level: str
    start: StartPoint
    goal: str
    route: CheckedRoute


def check_site_plan(
    sm: SiteMap,
    start_level: str,
    sp: StartPoint,
    goal_level: str,
    goal_id: str,
    raw: list[RawStep],
    constraints: PlanConstraints = NO_CONSTRAINTS,
) -> tuple[tuple[list[CheckedLeg], list[LiftRide]] | None, list[PlanIssue]]:
    """The legs and rides of a valid answer across levels, or None and every issue found
    (steps numbered as in the answer). ``constraints`` hold on the start level."""
    parts: list[tuple[int, list[RawStep], RawStep | None]] = []  # (offset, steps, ride)
    first = 0
    for k, step in enumerate(raw):
        if _RIDE.fullmatch(step.action):
            parts.append((first, raw[first:k], step))
            first = k + 1
    parts.append((first, raw[first:], None))
    legs: list[CheckedLeg] = []
    rides: list[LiftRide] = []
    level, at = start_level, sp
    for offset, steps, ride in parts:
        pm = sm.maps[level]
        cons = constraints if level == start_level else NO_CONSTRAINTS
        if ride is None:
            if level != goal_level:
                return None, [
                    PlanIssue(
                        IssueKind.WRONG_GOAL,
                        f"the plan ends on level {level}, but {goal_id} is on level "
                        f"{goal_level}; ride a lift there",
                        len(raw) or None,
                    )
                ]
            goal = goal_id
        else:
            k = offset + len(steps) + 1
            lift, to, why = _ride(sm, level, ride)
            if why:
                return None, [PlanIssue(IssueKind.WRONG_LIFT, why, k)]
            goal = lift.lobbies[level]
            if not steps and pm.places[goal].node == _node_at(pm, at):
                steps = [RawStep(goal, "arrive")]  # already at the lobby: straight in
        route, found = check_plan(pm, at, goal, steps, cons)
        if route is None:
            return None, [replace(i, step=i.step + offset if i.step else None) for i in found]
        legs.append(CheckedLeg(level, at, goal, route))
        if ride is not None:
            rides.append(LiftRide(lift.id, level, to))
            level, at = to, out_of_lift(sm, lift.id, to)
    return (legs, rides), []


def _ride(sm: SiteMap, level: str, step: RawStep):
    """(lift, level name, "") of a ride step, or (None, None, why it is wrong)."""
    site = sm.site
    m = _RIDE.fullmatch(step.action)
    ids = ", ".join(lift.id for lift in site.lifts_at(level))
    lift = next((k for k in site.lifts if k.id.casefold() == step.name.strip().casefold()), None)
    if lift is None:
        return None, None, f"{step.name!r} is not a lift; the lifts on level {level}: {ids}"
    if level not in lift.lobbies:
        return None, None, f"{lift.id} has no lobby on level {level}; its lifts: {ids}"
    try:
        to = site.level(m.group(1)).name
    except PmNavError:
        names = ", ".join(site.level_names)
        return None, None, f"{m.group(1)!r} is not a level; levels: {names}"
    if to not in lift.lobbies or to == level:
        served = ", ".join(lv for lv in lift.lobbies if lv != level)
        return None, None, f"{lift.id} goes from {level} to {served}, not to {to}"
    return lift, to, ""


def _node_at(pm, sp: StartPoint) -> str | None:
    """The map node a start point is on (None between nodes)."""
    seg = sp.segment
    return seg.a if sp.t <= 1e-9 else seg.b if sp.t >= 1 - 1e-9 else None


def site_plan_text(
    sm: SiteMap,
    levels: list[str],
    start_level: str,
    sp: StartPoint,
    goal_level: str,
    goal_id: str,
    inputs: str,
    ride_m: float,
) -> str:
    """The planning prompt across levels: the site, each of ``levels``' maps, the task."""
    if inputs not in SITE_INPUTS:
        raise PmNavError(
            f"planning input {inputs!r} cannot plan across levels: choose "
            f"{' or '.join(SITE_INPUTS)} (vlm.prompt)"
        )
    sections = []
    for name in levels:
        pm = sm.maps[name]
        text = pm.to_text().strip() if inputs == "h-pm" else environment_section(pm).strip()
        sections.append(f"# Level {name}\n\n{text}")
    note = (
        "The images are the annotated priori-maps of these levels, in this order: "
        if inputs == "h-pm"
        else "The images are the floor plans of these levels, in this order: "
    )
    site_section = sm.overview_text().strip() + "\n\n" + note + ", ".join(levels) + "."
    b = sm.maps[goal_level].building
    return template("h_cot_levels").substitute(
        kind=b.kind,
        building=sm.site.name,
        site_section=site_section,
        map_sections="\n\n".join(sections),
        start_level=start_level,
        goal_level=goal_level,
        goal=goal_id,
        goal_name=b.room(goal_id).display_name,
        start=start_description(sm.maps[start_level], sp),
        ride_m=f"{ride_m:.0f}",
    )


class SiteVlmPlanner:
    """Plans across levels with a VLM (checked per level, re-prompted, graph fallback)."""

    name = "vlm"

    def __init__(self, level_planner: VlmPlanner, ride_planner: SitePlanner | None = None):
        self.level_planner = level_planner
        self.graph = ride_planner or SitePlanner(max_gap=level_planner.max_gap)
        self.stats: PlanStats = level_planner.stats

    def plan(
        self,
        sm: SiteMap,
        start_level: str,
        start: Pose2D | str | StartPoint,
        goal: str,
        constraints: PlanConstraints = NO_CONSTRAINTS,
    ) -> SitePlan:
        """A plan across levels from the VLM, valid on every level, or the graph's."""
        vp = self.level_planner
        level = sm.site.level(start_level).name
        goal_level, goal_id = resolve_site_room(sm, goal)
        pm = sm.maps[level]
        sp = start_point(pm, start)
        if goal_level == level:
            p = vp.plan(pm, sp, goal_id, constraints)
            name = pm.building.room(goal_id).display_name
            return SitePlan(sm.site.name, (Leg(level, p),), (), level, goal_id, name, p.length)
        best = self.graph.plan(sm, level, sp, f"{goal_level}/{goal_id}", constraints)
        levels = list(dict.fromkeys(leg.level for leg in best.legs))
        text = site_plan_text(
            sm, levels, level, sp, goal_level, goal_id, vp.inputs, self.graph.ride_call_m
        )
        images = [map_image(sm.maps[lv], vp.inputs, vp.image_px) for lv in levels]
        messages = [user_message(text, images)]
        why, answers = "", 0
        for attempt in range(vp.tries):
            try:
                reply = vp.client.chat(messages, purpose=f"plan:{vp.inputs}:levels")
            except VlmError as err:
                why = str(err)
                self._count(answers, None, server_error=True)
                return self._fallback(best, f"the VLM failed: {why}")
            answers += 1
            checked, issues = self._score(
                sm, level, sp, goal_level, goal_id, reply.text, best, constraints
            )
            self.stats.issues.update(i.kind.value for i in issues)
            if checked is not None:
                self._count(answers, checked)
                return self._site_plan(
                    sm, goal_level, goal_id, checked, best, answers, constraints
                )
            why = "; ".join(str(i) for i in issues[:3])
            if attempt + 1 < vp.tries:
                messages = [*messages, {"role": "assistant", "content": reply.text}]
                messages.append(
                    {"role": "user", "content": repair_text([str(i) for i in issues], goal_id)}
                )
        self._count(answers, None)
        return self._fallback(best, f"no valid VLM plan in {answers} answers: {why}")

    def _score(self, sm, level, sp, goal_level, goal_id, text, best, constraints):
        try:
            raw = parse_plan(text)
        except ParseFailure as err:
            return None, [PlanIssue(IssueKind(err.kind), err.message)]
        checked, issues = check_site_plan(sm, level, sp, goal_level, goal_id, raw, constraints)
        detour = self.level_planner.max_detour
        if checked is None or detour is None:
            return checked, issues
        legs, rides = checked
        cost = sum(leg.route.length for leg in legs) + sum(
            self.graph.ride_cost(sm.site, r.from_level, r.to_level) for r in rides
        )
        if cost > best.cost * (1.0 + detour) + 1e-6:
            way = "; ".join(best.step_texts())
            return None, [
                PlanIssue(
                    IssueKind.DETOUR,
                    f"the route costs {cost:.1f} m (corridors and rides), more than "
                    f"{detour:.0%} above the cheapest ({best.cost:.1f} m, by {way}); take a "
                    "shorter way",
                )
            ]
        return checked, []

    def _site_plan(self, sm, goal_level, goal_id, checked, best, answers, constraints):
        legs, rides = checked
        vp = self.level_planner
        out = []
        for i, leg in enumerate(legs):
            r = leg.route
            avoid = constraints.avoid_landmarks if i == 0 else frozenset()
            xy = np.asarray(r.start_xy)
            plan = build_plan(
                sm.maps[leg.level], leg.start, leg.goal, list(r.nodes), r.length, xy,
                vp.max_gap, vp.name, avoid,
            )  # fmt: skip
            if i == len(legs) - 1:
                note = f"vlm ({vp.inputs}) across levels: valid on answer {answers}"
                plan = replace(plan, notes=(*plan.notes, note))
            out.append(Leg(leg.level, plan))
        cost = sum(leg.plan.length for leg in out) + sum(
            self.graph.ride_cost(sm.site, r.from_level, r.to_level) for r in rides
        )
        return SitePlan(
            sm.site.name, tuple(out), tuple(rides), goal_level, goal_id, best.goal_name, cost
        )

    def _fallback(self, best: SitePlan, what: str) -> SitePlan:
        if not self.level_planner.fallback:
            raise VlmError(what)
        log.warning("%s; planning with the graph planner", what)
        last = best.legs[-1]
        plan = replace(
            last.plan,
            planner="vlm->graph",
            notes=(*last.plan.notes, f"fallback to the graph planner: {what}"),
        )
        legs = (*best.legs[:-1], Leg(last.level, plan))
        return replace(best, legs=legs)

    def _count(self, answers: int, checked, server_error: bool = False) -> None:
        s = self.stats
        s.plans += 1
        s.reprompts += max(0, answers - 1)
        if server_error:
            s.server_errors += 1
            s.issues[IssueKind.SERVER_ERROR.value] += 1
        if checked is None:
            s.fallbacks += int(self.level_planner.fallback)
        elif answers == 1:
            s.valid_first += 1
        else:
            s.repaired += 1


def build(cfg, sm: SiteMap) -> SiteVlmPlanner:
    """The ``vlm`` planner across levels, as the config's ``vlm`` section describes it."""
    from pmnav_bt.backends import BackendDeps
    from pmnav_bt.vlm.planner import build as build_level_planner

    deps = BackendDeps(config=cfg, pm=sm.maps[sm.site.levels[0].name])
    return SiteVlmPlanner(build_level_planner(deps), SitePlanner(max_gap=cfg.planner.max_gap))
