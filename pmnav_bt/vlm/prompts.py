"""The planning and coarse-direction prompts (package data in ``pmnav_bt/vlm/prompts``).

Three planning inputs, as in the paper's Table 2:

- ``h-pm``: the H-CoT prompt (three steps: where the start is relative to the target;
  the key waypoints that lead there; first-person actions per landmark) with the
  structured priori-map text (segments, directions between key waypoints, places) and
  the annotated priori-map image;
- ``h-em``: the same H-CoT prompt with the raw environmental map (the floor plan with
  room numbers) and only the IDs a plan must use (key waypoints, rooms, landmarks);
- ``o-em``: an ordinary prompt with the raw environmental map and the same IDs.

Every input asks for the same JSON answer, so one parser and one validator serve all.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from functools import cache
from importlib import resources
from string import Template
from typing import Any, Literal

import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import compass
from pmnav_bt.map.priori_map import PrioriMap, natural_key
from pmnav_bt.planning.resolve import StartPoint
from pmnav_bt.vlm.client import fit_long_side, user_message

log = logging.getLogger(__name__)

PlanInput = Literal["o-em", "h-em", "h-pm"]
PLAN_INPUTS: tuple[str, ...] = ("o-em", "h-em", "h-pm")
INPUT_NAMES = {
    "o-em": "O-EM (ordinary prompt + environmental map)",
    "h-em": "H-EM (H-CoT prompt + environmental map)",
    "h-pm": "H-PM (H-CoT prompt + annotated priori-map)",
}


@cache
def template(name: str) -> Template:
    """A prompt template of the package by file stem (``h_cot``, ``repair``, ...)."""
    text = resources.files("pmnav_bt.vlm").joinpath("prompts", f"{name}.txt").read_text("utf-8")
    return Template(text)


def start_description(pm: PrioriMap, sp: StartPoint) -> str:
    """Where the robot is, for a prompt: segment, position, heading (the scripted server and
    a person read the same line)."""
    seg = sp.segment
    a, b = pm.node_xy(seg.a), pm.node_xy(seg.b)
    xy = a + sp.t * (b - a)
    where = f"on {seg.name} at ({xy[0]:.2f}, {xy[1]:.2f})"
    if sp.heading is None:
        return where + ", heading unknown (assume it faces along the segment, from a to b)"
    deg = math.degrees(sp.heading) % 360.0
    facing = f", facing {compass(sp.heading)} (heading {deg:.0f} deg, counter-clockwise from east)"
    return where + facing


def environment_section(pm: PrioriMap) -> str:
    b = pm.building
    wps = "\n".join(
        f"- {n.id}: {n.kind} at ({n.pos[0]:.1f}, {n.pos[1]:.1f})" for n in pm.key_waypoints
    )
    rooms = "\n".join(
        f"- {r.id}: {r.display_name}" for r in sorted(b.rooms, key=lambda r: natural_key(r.id))
    )
    lms = "\n".join(
        f"- {lm.id}: {lm.kind}, {lm.display_name}, at ({lm.pos[0]:.1f}, {lm.pos[1]:.1f})"
        for lm in b.landmarks
    )
    return template("environment_map_section").substitute(
        key_waypoints=wps, rooms=rooms, landmarks=lms or "- (none)"
    )


def plan_text(pm: PrioriMap, sp: StartPoint, goal_id: str, inputs: str) -> str:
    """The text of a planning prompt for ``inputs`` (o-em, h-em, h-pm)."""
    if inputs not in PLAN_INPUTS:
        raise PmNavError(f"unknown planning input {inputs!r}: choose {', '.join(PLAN_INPUTS)}")
    b = pm.building
    if inputs == "h-pm":
        section = template("priori_map_section").substitute(priori_map=pm.to_text().strip())
    else:
        section = environment_section(pm)
    fields = dict(
        kind=b.kind,
        building=b.name,
        map_section=section,
        goal=goal_id,
        goal_name=b.room(goal_id).display_name,
        start=start_description(pm, sp),
    )
    name = "ordinary" if inputs == "o-em" else "h_cot"
    return template(name).substitute(fields)


def map_image(pm: PrioriMap, inputs: str, long_side: int = 1280) -> np.ndarray:
    """The image a planning input shows (cached per map): annotated for h-pm, raw otherwise."""
    cache_ = pm.__dict__.setdefault("_vlm_images", {})
    key = ("pm" if inputs == "h-pm" else "em", long_side)
    if key not in cache_:
        cache_[key] = fit_long_side(_render(pm, annotated=key[0] == "pm"), long_side)
    return cache_[key]


def _render(pm: PrioriMap, annotated: bool) -> np.ndarray:
    from pmnav_bt.map.catalogue import builtin_buildings, resolve_building_path
    from pmnav_bt.render.annotate import render_annotated_map, render_environment_map

    draw = render_annotated_map if annotated else render_environment_map
    base = "."
    if pm.building.name in builtin_buildings():
        base = str(resolve_building_path(pm.building.name).parent)
    try:
        return draw(pm, base_dir=base)
    except (PmNavError, OSError) as err:  # the floor plan file is elsewhere: draw the map
        log.warning("map image without the floor plan (%s)", err)
        bare = replace(pm, building=pm.building.model_copy(update={"floor_plan": None}))
        return draw(bare, base_dir=base)


def plan_messages(
    pm: PrioriMap, sp: StartPoint, goal_id: str, inputs: str, image_px: int = 1280
) -> list[dict[str, Any]]:
    """The chat messages of a planning request: one user turn, text then the map image."""
    return [user_message(plan_text(pm, sp, goal_id, inputs), [map_image(pm, inputs, image_px)])]


def repair_text(issues: list[str], goal_id: str) -> str:
    """The re-prompt that quotes what was wrong with the last answer."""
    lines = "\n".join(f"- {i}" for i in issues)
    return template("repair").substitute(issues=lines, goal=goal_id)


@dataclass(frozen=True)
class CoarsePrompt:
    text: str
    angles_deg: tuple[int, ...]


def coarse_text(target: str, angles_deg: list[int]) -> str:
    """The coarse-direction question for a panorama with views at ``angles_deg``."""
    return template("coarse").substitute(
        n_views=len(angles_deg),
        angles=", ".join(f"{a:+d}" for a in angles_deg),
        target=target,
    )
