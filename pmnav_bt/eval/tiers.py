"""Episode difficulty tiers (PM-Nav RQ1), defined once: by path structure and length.

A tier is judged on the *corridor route* from the start to the goal: its length in paper
"steps" of ``STEP_M`` (to the tree's stop point, ``STOP_OFFSET_M`` from the door), whether
the goal is visible from the start, and how many turns and forks the route has.
``tier_definition()`` prints the definitions with the success and budget rules, for the
header of every result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pmnav_bt.eval.task import STOP_OFFSET_M, SUCCESS_RADIUS_M, budget_rule

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.map.priori_map import PrioriMap

STEP_M = 1.0  # one paper "step" (RQ1 step counts fit moves of about a metre)
VISIBLE_RANGE_M = 10.0  # a door sign is readable up to this distance
VISIBLE_HALF_FOV_DEG = 25.0  # door centre within +-this of the start heading (60 deg camera)
START_CLEARANCE_M = 1.5  # starts at least this far from any key waypoint (junction, end)
START_GRID_M = 0.05  # spacing of candidate start points along the centre lines


def start_candidates(pm: PrioriMap) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where an episode may start: points on the corridor centre lines every
    ``START_GRID_M``, at least ``START_CLEARANCE_M`` from every key waypoint. Returns their
    xy (N, 2), segment index (N,) and distance along the segment (N,)."""
    keys = np.array([n.pos for n in pm.key_waypoints], dtype=float)
    xy, seg, ss = [], [], []
    for k, sg in enumerate(pm.segments):
        a, b = pm.node_xy(sg.a), pm.node_xy(sg.b)
        s = np.arange(0.0, sg.length + 1e-9, START_GRID_M)
        p = a + (s / max(sg.length, 1e-9))[:, None] * (b - a)
        clear = np.linalg.norm(p[:, None, :] - keys[None], axis=2).min(axis=1)
        ok = clear >= START_CLEARANCE_M
        xy.append(p[ok])
        seg.append(np.full(int(ok.sum()), k))
        ss.append(s[ok])
    return np.concatenate(xy), np.concatenate(seg), np.concatenate(ss)


@dataclass(frozen=True)
class PathFacts:
    """The corridor route from a start pose to a goal room, and its structural facts."""

    length: float
    turns: int
    forks: int
    goal_visible: bool
    route: tuple[str, ...]  # priori-map nodes, ending at the goal node
    points: tuple[tuple[float, float], ...]  # polyline: start ... goal node, stop point


@dataclass(frozen=True)
class TierSpec:
    """One difficulty tier: route length in steps and the structure the route must have."""

    name: str
    min_steps: int
    max_steps: int
    goal_visible: bool | None  # required value; None: either
    min_turns: int
    max_turns: int | None
    min_forks: int
    max_forks: int | None
    paper: str  # the paper's words (RQ1)

    @property
    def length_band(self) -> tuple[float, float]:
        """Route length band in metres, [lo, hi): step counts rounded to the nearest step."""
        return (self.min_steps - 0.5) * STEP_M, (self.max_steps + 0.5) * STEP_M

    def accepts(self, facts: PathFacts) -> bool:
        lo, hi = self.length_band
        return (
            lo <= facts.length < hi
            and (self.goal_visible is None or facts.goal_visible == self.goal_visible)
            and within(facts.turns, self.min_turns, self.max_turns)
            and within(facts.forks, self.min_forks, self.max_forks)
        )

    def describe(self) -> str:
        lo, hi = self.length_band
        vis = {True: "goal visible", False: "goal not visible", None: "goal visible or not"}
        return (
            f"{self.name}: {vis[self.goal_visible]}; turns {_range(self.min_turns, self.max_turns)}"
            f"; forks {_range(self.min_forks, self.max_forks)}; "
            f"{self.min_steps}-{self.max_steps} steps (route {lo:.1f} <= l < {hi:.1f} m)"
            f"  [paper: {self.paper}]"
        )


def within(v: int, lo: int, hi: int | None) -> bool:
    """lo <= v <= hi, hi None meaning no upper bound."""
    return v >= lo and (hi is None or v <= hi)


def _range(lo: int, hi: int | None) -> str:
    if hi is None:
        return f">= {lo}"
    return f"= {lo}" if lo == hi else f"{lo}-{hi}"


TIERS: dict[str, TierSpec] = {
    t.name: t
    for t in (
        TierSpec(
            name="easy",
            min_steps=3,
            max_steps=5,
            goal_visible=True,
            min_turns=0,
            max_turns=0,
            min_forks=0,
            max_forks=0,
            paper="goal in view, reachable in 3-5 steps",
        ),
        TierSpec(
            name="medium",
            min_steps=6,
            max_steps=10,
            goal_visible=False,
            min_turns=1,
            max_turns=None,
            min_forks=0,
            max_forks=0,
            paper="goal not visible, at least one turn, 6-10 steps",
        ),
        TierSpec(
            name="hard",
            min_steps=11,
            max_steps=60,
            goal_visible=False,
            min_turns=2,
            max_turns=None,
            min_forks=1,
            max_forks=None,
            paper="several turns and fork selections, more than 10 steps",
        ),
    )
}
TIER_NAMES: tuple[str, ...] = tuple(TIERS)  # in display order
# The tier of an episode whose goal is on another level of a site, reached by lift
# (``sim/site_episodes.py``): judged by the levels, not by a route's length or shape, so it
# is no TierSpec. Only a site of several levels poses it.
CROSS_LEVEL = "cross_level"
ALL_TIERS: tuple[str, ...] = (*TIER_NAMES, CROSS_LEVEL)


def parse_tiers(text: str) -> list[str]:
    """'all', one tier name or a comma-separated list -> tier names; ValueError if unknown.
    'all' includes cross_level: a one-level building simply poses none of it."""
    if text.strip() == "all":
        return list(ALL_TIERS)
    names = [t.strip() for t in text.split(",") if t.strip()]
    bad = [t for t in names if t not in ALL_TIERS]
    if bad or not names:
        known = ", ".join(ALL_TIERS)
        raise ValueError(f"unknown tier {', '.join(bad) or text!r}: choose {known} or all")
    return names


def classify(facts: PathFacts) -> str | None:
    """The tier whose definition the route meets, or None."""
    return next((t.name for t in TIERS.values() if t.accepts(facts)), None)


def tier_definition(budget: str | None = None) -> str:
    """The tier definitions, the success rule and the budget rule, as text."""
    lines = [
        "Episode tiers (PM-Nav RQ1), by structure and corridor route length l from the start "
        f"to the goal stop point ({STOP_OFFSET_M:g} m from the door towards the corridor "
        f"centre); 1 step = {STEP_M:g} m:",
    ]
    lines += [f"- {t.describe()}" for t in TIERS.values()]
    lines += [
        f"Goal visible: the goal door is on the start's straight corridor (no key waypoint "
        f"between), within {VISIBLE_RANGE_M:g} m and +-{VISIBLE_HALF_FOV_DEG:g} deg of the "
        "start heading. Turn: the route bends by more than 30 deg at a waypoint. Fork: the "
        "route passes a branch waypoint (3+ corridors meet). The hard tier is capped at "
        f"{TIERS['hard'].max_steps} steps. Starts lie on a corridor centre line, at least "
        f"{START_CLEARANCE_M:g} m from any key waypoint, facing along the corridor. "
        f"Success: stop within {SUCCESS_RADIUS_M:g} m of the door point. SPL's shortest path: "
        "the free-space geodesic (corridors less the robot's radius, landmarks as obstacles) "
        "from the start to the success disc. " + (budget or budget_rule()),
        f"- {CROSS_LEVEL}: a start on one level of a site, the goal room on another, reached "
        "by lift (a site of several levels only). Success: stop within "
        f"{SUCCESS_RADIUS_M:g} m of the door on the goal level. SPL's shortest path: each "
        "leg's free-space geodesic (to the next lift's lobby, or the success disc) and the "
        "drive into each cabin and out. Budget: the rule above on the legs' corridor metres, "
        "and 100 actions a ride.",
    ]
    return "\n".join(lines)
