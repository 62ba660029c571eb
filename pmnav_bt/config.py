"""One typed configuration for a run: back ends, tree settings, simulator settings.

Loaded from a YAML file (every key optional) with dotted CLI overrides such as
``--set grounder.miss_rate=0.2``. Back ends are chosen here, not by flags threaded
through call chains.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from pmnav_bt.errors import ConfigError
from pmnav_bt.seams import CREATE3_MAX_ANGULAR, CREATE3_MAX_LINEAR


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid")


def _registered(seam: str):
    """A validator: ``backend`` must name a back end registered for ``seam``."""

    def check(cls, name: str) -> str:
        from pmnav_bt.registry import REGISTRIES

        try:
            REGISTRIES[seam].spec(name)
        except ConfigError as err:
            raise ValueError(str(err).split(": ", 1)[1]) from None
        return name

    return field_validator("backend")(check)


class GrounderConfig(_Section):
    backend: str = Field("sim_gt", description="grounder back end (pmnav backends lists them)")
    _check_backend = _registered("grounder")
    miss_rate: float = Field(0.0, ge=0.0, le=1.0, description="chance a readable sign is missed")
    false_positive_rate: float = Field(
        0.0, ge=0.0, le=1.0, description="chance another visible sign is read as the target"
    )
    mask_noise_px: int = Field(0, ge=0, description="random erosion/dilation and shift of masks")
    min_sign_pixels: int = Field(40, ge=1, description="a sign smaller than this is unreadable")
    max_range: float = Field(9.0, gt=0.0, description="a sign farther than this (m) is unreadable")
    hidden: list[str] = Field(
        default_factory=list, description="room/landmark IDs whose signs are never read"
    )


class CoarseConfig(_Section):
    backend: str = Field("detector", description="panorama views -> the view of the target")
    _check_backend = _registered("coarse")
    min_score: float = Field(0.3, ge=0.0, le=1.0, description="weaker detections are ignored")


class RefinerConfig(_Section):
    backend: str = Field("geometric", description="goal pixel -> bearing (and range)")
    _check_backend = _registered("refiner")


class PlannerConfig(_Section):
    backend: str = Field("graph", description="priori-map + start + goal -> plan")
    _check_backend = _registered("planner")
    max_gap: float = Field(8.0, gt=0.0, description="most metres between plan steps")


class TreeConfig(_Section):
    variant: Literal["pmnav", "coarse_only"] = Field(
        "pmnav", description="coarse_only: no grounding or refinement (paper Table 4)"
    )
    tick_hz: float = Field(10.0, gt=0.0, description="tree ticks per second of the clock")
    budget_actions: int = Field(500, ge=1, description="action budget (Habitat ObjectNav)")
    budget_path_factor: float = Field(
        3.0, gt=0.0, description="budget = max(budget_actions, factor * shortest path in actions)"
    )
    localization_attempts: int = Field(4, ge=1, description="localization tries")
    explore_distance: float = Field(2.0, gt=0.0, description="m explored between tries")
    search_range: float = Field(
        4.5, gt=0.0, description="drive until a target is this close (by the map) before searching"
    )
    search_attempts: int = Field(3, ge=1, description="searches for one landmark")
    research_distance: float = Field(
        2.0, gt=0.0, description="move this far towards a target not found before searching again"
    )
    replans: int = Field(2, ge=0, description="re-localize-and-replan recoveries")
    goal_offset: float = Field(0.6, ge=0.0, description="stop this far from the goal door")
    step_timeout_s: float = Field(180.0, gt=0.0, description="clock seconds per plan step")
    max_linear: float = Field(CREATE3_MAX_LINEAR, gt=0.0, description="m/s (Create 3)")
    max_angular: float = Field(CREATE3_MAX_ANGULAR, gt=0.0, description="rad/s (Create 3)")


class SimConfig(_Section):
    width: int = Field(320, ge=16, description="camera pixels (60 deg horizontal field)")
    height: int = Field(240, ge=16, description="camera pixels")
    odometry_noise: float = Field(
        0.02, ge=0.0, description="std of the relative error of each odometry increment"
    )


class Config(_Section):
    grounder: GrounderConfig = GrounderConfig()
    coarse: CoarseConfig = CoarseConfig()
    refiner: RefinerConfig = RefinerConfig()
    planner: PlannerConfig = PlannerConfig()
    tree: TreeConfig = TreeConfig()
    sim: SimConfig = SimConfig()


def _set_dotted(data: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    d = data
    for p in parts[:-1]:
        d = d.setdefault(p, {})
        if not isinstance(d, dict):
            raise ConfigError(f"override {key!r}: {p!r} is not a section")
    d[parts[-1]] = value


def load_config(path: str | Path | None = None, overrides: list[str] | tuple = ()) -> Config:
    """The configuration from ``path`` (optional) with ``key=value`` overrides applied."""
    data: dict = {}
    source = str(path) if path else "<defaults>"
    if path:
        try:
            data = yaml.safe_load(Path(path).read_text(encoding="utf-8")) or {}
        except OSError as err:
            raise ConfigError(f"{path}: cannot read config: {err.strerror}") from None
        except yaml.YAMLError as err:
            raise ConfigError(f"{path}: not valid YAML: {err}") from None
        if not isinstance(data, dict):
            raise ConfigError(f"{path}: expected a mapping of sections")
    for item in overrides:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"override {item!r}: expected section.key=value")
        _set_dotted(data, key.strip(), yaml.safe_load(raw))
    try:
        return Config.model_validate(data)
    except ValidationError as err:
        e = err.errors()[0]
        where = ".".join(str(p) for p in e["loc"])
        more = f" (and {len(err.errors()) - 1} more)" if len(err.errors()) > 1 else ""
        msg = e["msg"].removeprefix("Value error, ")
        raise ConfigError(f"{source}: {where}: {msg}{more}") from None
