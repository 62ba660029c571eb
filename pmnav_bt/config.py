"""One typed configuration for a run: back ends, tree settings, simulator settings.

Loaded from a YAML file (every key optional) with dotted CLI overrides such as
``--set grounder.miss_rate=0.2``. Back ends are chosen here, not by flags threaded
through call chains.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from pmnav_bt.errors import ConfigError


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid")


class GrounderConfig(_Section):
    backend: Literal["sim_gt"] = "sim_gt"
    miss_rate: float = Field(0.0, ge=0.0, le=1.0)
    false_positive_rate: float = Field(0.0, ge=0.0, le=1.0)
    mask_noise_px: int = Field(0, ge=0)
    min_sign_pixels: int = Field(40, ge=1)
    max_range: float = Field(9.0, gt=0.0)
    hidden: list[str] = Field(
        default_factory=list, description="room/landmark IDs whose signs are never read"
    )


class CoarseConfig(_Section):
    backend: Literal["detector"] = "detector"
    min_score: float = Field(0.3, ge=0.0, le=1.0)


class RefinerConfig(_Section):
    backend: Literal["geometric"] = "geometric"


class PlannerConfig(_Section):
    backend: Literal["graph"] = "graph"
    max_gap: float = Field(8.0, gt=0.0)


class TreeConfig(_Section):
    variant: Literal["pmnav", "coarse_only"] = "pmnav"
    tick_hz: float = Field(10.0, gt=0.0)
    budget_actions: int = Field(500, ge=1)
    budget_path_factor: float = Field(
        3.0, gt=0.0, description="budget = max(budget_actions, factor * shortest path in actions)"
    )
    localization_attempts: int = Field(4, ge=1)
    explore_distance: float = Field(2.0, gt=0.0)
    search_range: float = Field(
        4.5, gt=0.0, description="drive until a target is this close (by the map) before searching"
    )
    search_attempts: int = Field(3, ge=1)
    research_distance: float = Field(
        2.0, gt=0.0, description="move this far towards a target not found before searching again"
    )
    replans: int = Field(2, ge=0)
    approach_offset: float = Field(1.0, ge=0.0, description="stop this far from a landmark door")
    goal_offset: float = Field(0.6, ge=0.0, description="stop this far from the goal door")
    step_timeout_s: float = Field(180.0, gt=0.0, description="clock seconds per plan step")
    max_linear: float = Field(0.306, gt=0.0)
    max_angular: float = Field(1.9, gt=0.0)


class SimConfig(_Section):
    width: int = Field(320, ge=16)
    height: int = Field(240, ge=16)
    odometry_noise: float = Field(
        0.02, ge=0.0, description="std of the relative error of each odometry increment"
    )
    seed: int = 0


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
        raise ConfigError(f"{source}: {where}: {e['msg']}{more}") from None
