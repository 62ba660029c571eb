"""Navigation metrics: success, SPL, soft SPL, SDF, per-episode results and a per-tier table.

- Success: the agent stops within ``SUCCESS_RADIUS_M`` of the goal room's door point.
- SPL = S * l / max(l, p) (Anderson et al. 2018, "On Evaluation of Embodied Navigation
  Agents"; habitat-lab), l the shortest path length, p the length the agent travelled.
  l is the free-space geodesic from the start to the success region
  (:mod:`pmnav_bt.eval.geodesic`), so only an optimal path scores 1.
- Soft SPL (habitat-lab) = max(0, 1 - d_T / l) * l / max(l, p), d_T the geodesic
  distance to the success region where the agent stopped (``distance_to_goal``).
- SDF (PM-Nav paper, eq. 1) is implemented as S * 2 / max(2, d), d the number of
  localisation attempts. The paper prints d / max(2, d), which *rewards* more attempts;
  its Table 3 only fits 2 / max(2, d), so that is what this module computes.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field, fields
from typing import Any

import numpy as np

from pmnav_bt.eval.task import SUCCESS_RADIUS_M
from pmnav_bt.eval.tiers import TIER_NAMES

# Tiers in display order; other tier names follow in alphabetical order.
TIER_ORDER = TIER_NAMES


def success(
    stop_xy: Sequence[float], door_xy: Sequence[float], radius: float = SUCCESS_RADIUS_M
) -> bool:
    """True when the stop position lies within ``radius`` metres of the door point."""
    return math.dist(tuple(stop_xy[:2]), tuple(door_xy[:2])) <= radius


def spl(succeeded: bool | float, shortest: float, travelled: float) -> float:
    """Success weighted by path length for one episode: S * l / max(l, p), in [0, 1]."""
    if not succeeded:
        return 0.0
    if shortest < 0 or travelled < 0:
        raise ValueError("path lengths must be non-negative")
    longest = max(shortest, travelled)
    return 1.0 if longest == 0 else float(shortest / longest)


def soft_spl(shortest: float, distance_to_goal: float, travelled: float) -> float:
    """Habitat's soft SPL: progress towards the goal, max(0, 1 - d_T / l), weighted by
    l / max(l, p). With l = 0 the progress is 1 if the agent is still at the goal."""
    if shortest < 0 or travelled < 0 or distance_to_goal < 0:
        raise ValueError("distances must be non-negative")
    if shortest == 0:
        return 1.0 if distance_to_goal == 0 else 0.0
    progress = max(0.0, 1.0 - distance_to_goal / shortest)
    return float(progress * shortest / max(shortest, travelled))


def sdf_term(succeeded: bool | float, attempts: int) -> float:
    """One trial's SDF term: S * 2 / max(2, d) (the form that fits the paper's Table 3)."""
    if attempts < 0:
        raise ValueError("attempts must be non-negative")
    return float(bool(succeeded)) * 2.0 / max(2, attempts)


def sdf(successes: Sequence[bool | float], attempts: Sequence[int]) -> float:
    """Success weighted by detection frequency over N trials: mean of S_i * 2 / max(2, d_i)."""
    if len(successes) != len(attempts):
        raise ValueError("successes and attempts must have the same length")
    if not successes:
        return 0.0
    return float(np.mean([sdf_term(s, d) for s, d in zip(successes, attempts, strict=True)]))


@dataclass
class EpisodeResult:
    """The outcome of one navigation episode.

    ``failure_reason`` is None on success, otherwise a short code or sentence
    ("step budget exhausted", "stopped 2.3 m from the door"). ``error`` is set instead
    when the episode could not be run (a crash, a changed building file): such episodes
    are counted apart, not as navigation failures. ``shortest_path_length`` is SPL's l,
    ``distance_to_goal`` the geodesic from the stop to the success region,
    ``distance_to_door`` the straight line from the stop to the door point.
    ``trace`` optionally holds the visited poses or tree events. ``collisions`` counts the
    robot's contact events with anything (walls, clutter, people); ``people_contacts`` the
    times the robot and a person touched, whoever moved (the crowd's count, so a person
    walking into a standing robot counts too); None in results made before it was recorded.
    """

    episode_id: str
    tier: str
    success: bool
    spl: float
    path_length: float  # metres travelled
    steps: int  # actions (or control commands) issued
    collisions: int = 0
    wall_time: float = 0.0  # seconds
    failure_reason: str | None = None
    shortest_path_length: float = float("nan")  # free-space geodesic to the success region
    distance_to_goal: float = float("nan")  # geodesic from the stop to the success region
    building: str = ""
    trace: list[Any] | None = None
    soft_spl: float = float("nan")
    distance_to_door: float = float("nan")  # straight line from the stop to the door point
    route_length: float = float("nan")  # corridor route (tiers and budget), metres
    error: str | None = None
    people_contacts: int | None = None
    rides: int | None = None  # lift rides on the episode's route (cross_level); else None
    lifts_full: int | None = None  # calls the lift answered full (cross_level); else None

    def to_dict(self, with_trace: bool = False) -> dict[str, Any]:
        d = asdict(self)
        if not with_trace:
            d.pop("trace")
        return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EpisodeResult:
        """The inverse of ``to_dict``: None in a float field reads back as NaN."""
        floats = {f.name for f in fields(cls) if f.type in ("float", float)}
        return cls(**{k: (math.nan if k in floats and v is None else v) for k, v in d.items()})


@dataclass(frozen=True)
class TierRow:
    """Aggregates over the episodes of one tier (SR, SPL, soft SPL in percent).

    ``episodes`` counts those that ran; ``errors`` those that could not run, which are
    left out of every mean.
    """

    tier: str
    episodes: int
    sr: float
    spl: float
    mean_steps: float
    mean_path_length: float
    collisions: int
    soft_spl: float = float("nan")
    mean_distance_to_goal: float = float("nan")
    errors: int = 0


@dataclass
class TierTable:
    """SR/SPL per tier, plus an "all" row; renders as Markdown or JSON."""

    rows: list[TierRow] = field(default_factory=list)

    def row(self, tier: str) -> TierRow:
        return next(r for r in self.rows if r.tier == tier)

    def to_markdown(self, digits: int = 1) -> str:
        head = (
            "| tier | episodes | SR (%) | SPL (%) | soft SPL (%) | distance to goal (m) | "
            "mean steps | mean path (m) | collisions | errors |"
        )
        lines = [head, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in self.rows:
            lines.append(
                f"| {r.tier} | {r.episodes} | {r.sr:.{digits}f} | {r.spl:.{digits}f} | "
                f"{r.soft_spl:.{digits}f} | {r.mean_distance_to_goal:.2f} | "
                f"{r.mean_steps:.1f} | {r.mean_path_length:.1f} | {r.collisions} | {r.errors} |"
            )
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict[str, Any]:
        return {"tiers": [asdict(r) for r in self.rows]}

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent)


def _tier_key(tier: str) -> tuple[int, str]:
    return (TIER_ORDER.index(tier), "") if tier in TIER_ORDER else (len(TIER_ORDER), tier)


def _mean(values: list[float]) -> float:
    return float(np.mean(values)) if values else float("nan")


def _row(tier: str, all_rs: list[EpisodeResult]) -> TierRow:
    rs = [r for r in all_rs if r.error is None]
    return TierRow(
        tier=tier,
        episodes=len(rs),
        sr=100.0 * _mean([float(bool(r.success)) for r in rs]),
        spl=100.0 * _mean([r.spl for r in rs]),
        mean_steps=_mean([r.steps for r in rs]),
        mean_path_length=_mean([r.path_length for r in rs]),
        collisions=int(sum(r.collisions for r in rs)),
        soft_spl=100.0 * _mean([r.soft_spl for r in rs]),
        mean_distance_to_goal=_mean([r.distance_to_goal for r in rs]),
        errors=len(all_rs) - len(rs),
    )


@dataclass(frozen=True)
class ContactTotals:
    """One variant's contacts over the episodes that ran: the robot's collisions with
    anything and its contacts with people, totals (the targets are per 100 episodes).
    ``unrecorded``: episodes whose results predate the people count (left out of it)."""

    episodes: int
    collisions: int
    people_contacts: int
    unrecorded: int = 0

    def per_100_text(self) -> str:
        """Collisions per 100 episodes, one decimal; "-" when no episode ran."""
        return f"{100.0 * self.collisions / self.episodes:.1f}" if self.episodes else "-"

    def people_text(self) -> str:
        """The people count, saying how many episodes did not record it."""
        if self.unrecorded == self.episodes and self.episodes:
            return "not recorded"
        note = f" ({self.unrecorded} of {self.episodes} not recorded)" if self.unrecorded else ""
        return f"{self.people_contacts}{note}"


def contact_totals(results: Iterable[EpisodeResult]) -> ContactTotals:
    """Collisions and people contacts summed over the episodes that ran (errors left out)."""
    rs = [r for r in results if r.error is None]
    people = [r.people_contacts for r in rs if r.people_contacts is not None]
    return ContactTotals(
        episodes=len(rs),
        collisions=int(sum(r.collisions for r in rs)),
        people_contacts=int(sum(people)),
        unrecorded=len(rs) - len(people),
    )


def aggregate_by_tier(results: Iterable[EpisodeResult], overall: bool = True) -> TierTable:
    """SR, SPL and soft SPL (percent) per tier, in tier order, then an "all" row.

    Errored episodes (``error`` set) are counted per row and left out of the means.
    """
    results = list(results)
    by: dict[str, list[EpisodeResult]] = {}
    for r in results:
        by.setdefault(r.tier, []).append(r)
    rows = [_row(t, by[t]) for t in sorted(by, key=_tier_key)]
    if overall and results:
        rows.append(_row("all", results))
    return TierTable(rows)


def results_to_json(
    results: Iterable[EpisodeResult], with_trace: bool = False, indent: int | None = 2
) -> str:
    """Per-episode results as a JSON list."""
    return json.dumps([r.to_dict(with_trace) for r in results], indent=indent)
