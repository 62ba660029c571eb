"""One typed configuration for a run: back ends, tree settings, simulator settings.

Loaded from a YAML file (every key optional) with dotted CLI overrides such as
``--set grounder.miss_rate=0.2``. Back ends are chosen here, not by flags threaded
through call chains.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from pmnav_bt.errors import ConfigError, PmNavError
from pmnav_bt.eval.task import BUDGET_ACTIONS, BUDGET_PATH_FACTOR, STOP_OFFSET_M
from pmnav_bt.loading import InputFileError, load_yaml, parse_yaml_value
from pmnav_bt.planning.plan import MAX_GAP_M
from pmnav_bt.seams import CREATE3_MAX_ANGULAR, CREATE3_MAX_LINEAR

# The pixel-goal policy's reliable range (m): its skill eval (docs/pixelnav.md) gives SR 100 %
# at 1-2 m, 90 % at 2-3 m, 84.6 % at 3-4 m and 64 % at 4-5 m from the door.
POLICY_RANGE_M = 4.0


class _Section(BaseModel):
    # strict: "1" or true is not a number; ranges keep a run finite in time and memory.
    model_config = ConfigDict(extra="forbid", strict=True)


def _named(registry, name: str) -> str:
    """``name`` if ``registry`` (a ``registry.Named``) holds it; else the registry's one-line
    error (the names it holds, the nearest one) as a validation error of the field."""
    try:
        registry.spec(name)
    except ConfigError as err:
        raise ValueError(str(err).split(": ", 1)[1]) from None
    return name


def _registered(seam: str):
    """A validator: ``backend`` must name a back end registered for ``seam``."""

    def check(cls, name: str) -> str:
        from pmnav_bt.registry import REGISTRIES

        return _named(REGISTRIES[seam], name)

    return field_validator("backend")(check)


class GrounderConfig(_Section):
    """The grounder: reads door and landmark signs, and finds floor and walls, in a view.
    The `miss_rate` ... `hidden` keys shape the `sim_gt` oracle only; see
    [perception.md](perception.md) for the `ocr` and `gdino_sam` back ends."""

    backend: str = Field(
        "ocr",
        description="grounder back end (pmnav backends lists them); sim_gt: the simulator's "
        "labels, an oracle",
    )
    _check_backend = _registered("grounder")
    miss_rate: float = Field(0.0, ge=0.0, le=1.0, description="chance a readable sign is missed")
    false_positive_rate: float = Field(
        0.0, ge=0.0, le=1.0, description="chance another visible sign is read as the target"
    )
    mask_noise_px: int = Field(
        0, ge=0, le=100, description="random erosion/dilation and shift of masks"
    )
    min_sign_pixels: int = Field(
        40, ge=1, le=1_000_000, description="a sign smaller than this is unreadable"
    )
    max_range: float = Field(
        9.0, gt=0.0, le=1000.0, description="a sign farther than this (m) is unreadable"
    )
    hidden: list[str] = Field(
        default_factory=list, description="room/landmark IDs whose signs are never read"
    )
    # -- ocr and gdino_sam (real perception) --
    ocr_threads: int = Field(1, ge=1, description="ocr, gdino_sam: onnxruntime threads per model")
    ocr_max_candidates: int = Field(
        4, ge=1, description="ocr, gdino_sam: sign plates read per frame"
    )
    ocr_min_score: float = Field(
        0.6,
        ge=0.0,
        le=1.0,
        description="ocr, gdino_sam: text lines read with a lower score are dropped",
    )
    pictograms: bool = Field(
        True,
        description="ocr: read pictogram plates (toilets) whose text names nothing, "
        "with the shipped classifier (perception/pictograms.py)",
    )
    sign_to_door: float = Field(
        1.14, gt=0.0, description="m from a door sign's centre to its door's centre"
    )
    door_side: Literal["left", "right"] = Field(
        "left", description="side of its sign a door is on when the image cannot tell"
    )
    door_width: float = Field(1.16, gt=0.0, description="m, with the frame")
    door_height: float = Field(2.18, gt=0.0, description="m, with the frame")
    gdino_path: str = Field(
        "", description="gdino_sam: local folder of a GroundingDINO model (transformers)"
    )
    sam_path: str = Field("", description="gdino_sam: local folder of a SAM model (transformers)")
    box_threshold: float = Field(0.35, ge=0.0, le=1.0, description="gdino_sam: box score")
    text_threshold: float = Field(0.25, ge=0.0, le=1.0, description="gdino_sam: phrase score")


class CoarseConfig(_Section):
    """Coarse direction: which view of a panorama shows the target."""

    backend: str = Field("detector", description="panorama views -> the view of the target")
    _check_backend = _registered("coarse")
    min_score: float = Field(0.3, ge=0.0, le=1.0, description="weaker detections are ignored")


class RefinerConfig(_Section):
    """The refiner: the goal pixel in the chosen view -> a bearing and range to the door.
    It serves the full `pmnav` variant; the coarse-only ablation of the paper's Table 4 is a
    tree shape, so `tree.variant` is its one switch: `coarse_only` leaves the grounding step
    out of the tree and does not call the refiner (the target is taken straight ahead of the
    view it was seen in, at the distance the map predicts), and `refiner.backend` has no
    `coarse_only` value."""

    backend: str = Field("geometric", description="goal pixel -> bearing (and range)")
    _check_backend = _registered("refiner")
    weights: str = Field(
        "", description="pixelnav: a .safetensors (its .json beside it); empty: the shipped model"
    )
    regrounding: int = Field(
        8, ge=1, le=64, description="pixelnav: policy steps between re-groundings of the goal"
    )
    policy_range: float = Field(
        POLICY_RANGE_M,
        gt=0.0,
        le=100.0,
        description="pixelnav: the policy approaches a door at most this far (m) on the map "
        "when grounded; farther, the map approach (chosen from the first, 16-frame model's "
        "skill eval: SR >= 84.6 % up to 4 m; docs/pixelnav.md)",
    )


class PlannerConfig(_Section):
    """The global planner: the priori-map, a start and a goal room -> a plan of
    `{landmark: action}` steps."""

    backend: str = Field("graph", description="priori-map + start + goal -> plan")
    _check_backend = _registered("planner")
    max_gap: float = Field(
        MAX_GAP_M, gt=0.0, le=1000.0, description="most metres between plan steps"
    )


class VlmConfig(_Section):
    """An OpenAI-compatible chat-completions server (vLLM, Ollama, llama.cpp, OpenAI) for the
    `vlm` planner and coarse-direction back ends (see [vlm.md](vlm.md))."""

    base_url: str = Field(
        "http://127.0.0.1:8000/v1", description="server URL up to /v1 (chat/completions is added)"
    )
    model: str = Field("", description="model name the server serves (required for vlm back ends)")
    api_key_env: str = Field(
        "PMNAV_VLM_API_KEY", description="environment variable holding the API key (never logged)"
    )
    timeout_s: float = Field(60.0, gt=0.0, description="seconds per HTTP request")
    retries: int = Field(3, ge=0, description="retries after a 429, a 5xx or a dropped connection")
    backoff_s: float = Field(
        1.0, ge=0.0, description="first retry delay, doubled each retry (a Retry-After header wins)"
    )
    max_tokens: int = Field(1024, ge=1, description="most tokens an answer may have")
    temperature: float = Field(0.0, ge=0.0, le=2.0, description="sampling temperature")
    prompt: Literal["h-pm", "h-em", "o-em"] = Field(
        "h-pm",
        description="planning prompt: H-CoT + annotated map (h-pm), H-CoT + raw map (h-em), "
        "ordinary (o-em)",
    )
    plan_tries: int = Field(
        3, ge=1, description="VLM answers per plan (the first, then re-prompts quoting errors)"
    )
    max_detour: float = Field(
        0.5,
        ge=0.0,
        description="a plan longer than the shortest by more than this is an error (detour)",
    )
    fallback: bool = Field(
        True, description="plan with the graph planner when no VLM answer is valid or it fails"
    )
    image_px: int = Field(1280, ge=64, description="long side of the map image sent, pixels")
    usage_log: str = Field("", description="append one JSON line per call here (tokens, latency)")
    plan_log: str = Field(
        "", description="append one JSON line per plan here (outcome, answers, issues)"
    )


class TreeConfig(_Section):
    """The behaviour tree. The defaults of `planner.max_gap`, `tree.budget_actions`,
    `tree.budget_path_factor` and `tree.goal_offset` are defined once in the code
    (`pmnav_bt/planning/plan.py` `MAX_GAP_M`, `pmnav_bt/eval/task.py`), which every command
    uses: the action budget of an episode is
    `max(budget_actions, ceil(budget_path_factor * route / 0.25 m))`, the route being the
    corridor route from the start to the stop point `goal_offset` from the door. Success is
    stopping within 1 m of the door (`pmnav_bt/eval/task.py` `SUCCESS_RADIUS_M`), so
    `goal_offset` must stay below 1 m."""

    variant: str = Field(
        "pmnav",
        description="the tree, by name (registered in pmnav_bt/tree_variants.py, where its "
        "context and tree are built from): pmnav; coarse_only: no "
        "grounding or refinement (paper Table 4); mapless: the map-less frontier-exploring "
        "baseline (docs/baseline.md)",
    )

    @field_validator("variant")
    @classmethod
    def _registered_variant(cls, name: str) -> str:
        from pmnav_bt.tree_variants import TREE_VARIANTS

        return _named(TREE_VARIANTS, name)

    tick_hz: float = Field(
        10.0, ge=0.5, le=1000.0, description="tree ticks per second of the clock"
    )
    budget_actions: int = Field(
        BUDGET_ACTIONS, ge=1, le=100_000, description="action budget (Habitat ObjectNav)"
    )
    budget_path_factor: float = Field(
        BUDGET_PATH_FACTOR,
        gt=0.0,
        le=100.0,
        description="budget = max(budget_actions, factor * corridor route in forward steps)",
    )
    localization_doors: bool = Field(
        True,
        description="localization: doors seen along the walls (door_sightings) weigh the "
        "corridor belief, from 12 m, where signs are read from 3.5 m",
    )
    localization_walls: str | None = Field(
        None,
        description="localization: the walls the corridor belief weighs depth against, by "
        "name (pmnav_bt/pose/evidence/floor_model.py): corridors (the building file's "
        "corridor rectangles) or grid (the building's floor_plan.ros_map as a likelihood "
        "field, as AMCL's); unset: grid where the building has one (the real walls: lobbies, "
        "alcoves and corridors wider than drawn), else corridors",
    )

    @field_validator("localization_walls")
    @classmethod
    def _registered_walls(cls, name: str | None) -> str | None:
        from pmnav_bt.pose.evidence.floor_model import WALL_MODELS

        return None if name is None else _named(WALL_MODELS, name)

    localization_attempts: int = Field(
        10, ge=1, le=100, description="localization tries (panoramas) before giving up"
    )
    explore_distance: float = Field(
        16.0, gt=0.0, le=100.0, description="at most this far (m) along the corridor between tries"
    )
    search_range: float | None = Field(
        None,
        gt=0.0,
        le=100.0,
        description="drive until a target is this close (by the map) before searching; "
        "unset: from the grounder's read range (pmnav_bt/perception/read_range.py)",
    )
    search_attempts: int = Field(
        4,
        ge=1,
        le=100,
        description="searches for one landmark: at search_range, then every "
        "research_distance on, up to level with it (a sign on the door's far side is readable "
        "only from there)",
    )
    research_distance: float | None = Field(
        None,
        gt=0.0,
        le=100.0,
        description="move this far towards a target not found before searching again; "
        "unset: half the search range, at most 2 m",
    )
    active_reads: int = Field(
        2,
        ge=0,
        le=10,
        description="times a search drives to read a plate it saw but could not read near "
        "the target, before moving on (behaviours/active_read.py); 0: never",
    )
    replans: int = Field(2, ge=0, le=100, description="re-localize-and-replan recoveries")
    goal_offset: float = Field(
        STOP_OFFSET_M, ge=0.0, le=10.0, description="stop this far from the goal door"
    )
    step_timeout_s: float = Field(
        180.0, gt=0.0, le=86_400.0, description="clock seconds per plan step"
    )
    local_planner: str = Field(
        "direct",
        description="how a drive steers to its goal, by name (pmnav_bt/local_planner/steering.py): "
        "direct (straight at it; what stands in the way holds the drive, clutter is gone round "
        "by a detour point) or dwa (a rolling local costmap from depth and the dynamic window "
        "approach within the body's limits: clutter is driven round as it comes)",
    )

    @field_validator("local_planner")
    @classmethod
    def _registered_steering(cls, name: str) -> str:
        from pmnav_bt.local_planner.steering import STEERINGS

        return _named(STEERINGS, name)

    max_linear: float = Field(CREATE3_MAX_LINEAR, gt=0.0, le=5.0, description="m/s (Create 3)")
    max_angular: float = Field(CREATE3_MAX_ANGULAR, gt=0.0, le=10.0, description="rad/s (Create 3)")
    lift_wait_s: float = Field(
        180.0, gt=0.0, le=3600.0, description="clock seconds a lift may take to open its door at "
        "the lobby after a call (LIFT_NOT_COMING); a hospital's lifts at a busy hour take 1-3 min",
    )
    lift_ride_s: float = Field(
        120.0, gt=0.0, le=3600.0, description="clock seconds from asking for a level inside the "
        "cabin to its door open there (LIFT_NOT_COMING)",
    )
    lift_full_tries: int = Field(
        3, ge=1, le=20, description="lifts that come full let go before giving up (LIFT_FULL)"
    )
    lift_full_wait_s: float = Field(
        60.0, ge=0.0, le=600.0, description="the longest wait, clock seconds, for a full lift "
        "let go to shut its doors before it is called again (a call before they shut opens "
        "them on the same cabin); people boarding hold doors open up to a minute",
    )


class SimConfig(_Section):
    """The simulator: its camera, its odometry's noise and where its walls come from."""

    width: int = Field(320, ge=16, le=1920, description="camera pixels (60 deg horizontal field)")
    height: int = Field(240, ge=16, le=1080, description="camera pixels")
    reading_width: int = Field(
        640,
        ge=0,
        le=1920,
        description="pixels: the camera also offers each view this wide for reading signs "
        "(only the plates' crops are made, when the grounder reads; the tree's other checks "
        "keep width x height; the reader's range follows it, docs/perception.md); 0 or at "
        "most width: none",
    )
    odometry_noise: float = Field(
        0.02, ge=0.0, le=1.0, description="std of the relative error of each odometry increment"
    )
    walls: Literal["corridors", "grid"] = Field(
        "corridors",
        description="walls from the annotated corridors, or from the ros_map grid's occupied cells "
        "(grid; docs/real-maps.md)",
    )


# The [min, max] pairs of the world section, and the limits of their numbers.
_PAIR_LIMITS = {
    "people_speed": (0.1, 3.0),
    "light_level": (0.2, 2.0),
    "camera_exposure": (0.2, 5.0),
}


def _pair(name: str, what: str):
    """A [min, max] field whose numbers lie within ``_PAIR_LIMITS[name]``; default [1, 1]."""
    lo, hi = _PAIR_LIMITS[name]
    return Field(
        [1.0, 1.0],
        min_length=2,
        max_length=2,
        description=f"[min, max] {what}; {lo} <= min <= max <= {hi}",
    )


# The realistic preset: what a weekday corridor of a hospital, school or office looks like.
# A clutter item every 5-10 m of wall (benches, chairs, carts, beds, plants, notice boards:
# 1.4 per 10 m, a fifth of them standing in front of a sign); a few people per 100 m of
# corridor walking at 0.8-1.4 m/s (typical indoor walking speeds), a third of them pausing;
# a third of the doors open and one in ten glazed; light 25 % dimmer to 20 % brighter than
# the clean world's, from any side; a consumer camera's noise (2 % of full scale), auto
# exposure off by up to 20 %, and 20 ms exposure (motion blur while turning); signage and
# colours drawn per building and seed from the kinds real buildings use.
WORLD_PRESETS: dict[str, dict[str, Any]] = {
    "clean": {},
    "realistic": {
        "signage": "random",
        "appearance": "random",
        "clutter_per_10m": 1.4,
        "clutter_before_signs": 0.2,
        "people_per_100m": 3.0,
        "people_speed": [0.8, 1.4],
        "people_pausing": 0.33,
        "doors_open": 0.33,
        "doors_glass": 0.1,
        "light_level": [0.75, 1.2],
        "light_turn_deg": 180.0,
        "camera_noise": 0.02,
        "camera_exposure": [0.8, 1.2],
        "camera_exposure_time": 0.02,
    },
}


class WorldConfig(_Section):
    """What fills the simulated world beyond the building file: signage styles, clutter,
    people, doors, light and the camera's flaws. `preset` chooses every other key's default:
    `clean` is the world the paper's tables were measured in (one sign style, bare
    corridors, closed doors, perfect light and camera); `realistic` is a weekday hospital or
    school corridor (the values and why: `WORLD_PRESETS` in pmnav_bt/config.py,
    docs/worlds.md). A key set beside the preset overrides it
    (`--set world.preset=realistic --set world.people_per_100m=0`). Everything random is
    drawn from the episode's seed, so every episode is reproducible."""

    preset: Literal["clean", "realistic"] = Field(
        "clean", description="the defaults of every other key of this section"
    )
    signage: Literal["file", "random"] = Field(
        "file",
        description="sign plates as the building file's signage section says (today's plate "
        "where it says nothing), or random: what the file leaves unset is drawn per building "
        "and seed from real practice (sizes, fonts, colours, mountings, layouts)",
    )
    appearance: Literal["clean", "random"] = Field(
        "clean", description="wall, floor and door colours and textures: today's, or drawn per "
        "building and seed from real palettes",
    )
    clutter_per_10m: float = Field(
        0.0, ge=0.0, le=5.0, description="clutter items along the walls per 10 m of wall"
    )
    clutter_before_signs: float = Field(
        0.0, ge=0.0, le=1.0, description="fraction of the clutter placed in front of a sign"
    )
    people_per_100m: float = Field(
        0.0, ge=0.0, le=50.0, description="walking people per 100 m of corridor"
    )
    people_speed: list[float] = _pair("people_speed", "walking speed, m/s")
    people_pausing: float = Field(
        0.0, ge=0.0, le=1.0, description="fraction of the people who stop now and then"
    )
    doors_open: float = Field(0.0, ge=0.0, le=1.0, description="fraction of doors standing open")
    doors_glass: float = Field(0.0, ge=0.0, le=1.0, description="fraction of doors glazed")
    fire_doors_closed: float = Field(
        0.0, ge=0.0, le=1.0, description="probability that each fire door (a landmark of kind "
        "fire_door) is shut across its corridor, else held open (sim/scene/fire_doors.py; 0 in "
        "both presets)",
    )
    light_level: list[float] = _pair("light_level", "light level, 1 = the clean world's")
    light_turn_deg: float = Field(
        0.0, ge=0.0, le=180.0, description="the light's direction turns by up to this (deg)"
    )
    camera_noise: float = Field(
        0.0, ge=0.0, le=0.5, description="std of the camera's pixel noise, fraction of 255"
    )
    camera_exposure: list[float] = _pair("camera_exposure", "exposure gain per episode")
    camera_exposure_time: float = Field(
        0.0, ge=0.0, le=0.2, description="s the shutter is open (motion blur while turning)"
    )
    lift_full_p: float = Field(
        0.0, ge=0.0, le=1.0, description="probability that a lift answering a call comes with no "
        "room in it (people and a cart; sim/lift.py; 0 in both presets)",
    )
    stale_map: float = Field(
        0.0, ge=0.0, le=1.0, description="probability that the world differs from the map the "
        "robot gets by one change on the route (sim/scene/stale_map.py; 0 in both presets)",
    )
    stale_kinds: list[Literal["renamed", "moved", "closed"]] = Field(
        ["renamed", "moved", "closed"], min_length=1, max_length=3,
        description="the changes a stale map may have: a room renamed, a landmark moved, a "
        "corridor closed (where another way remains)",
    )

    @model_validator(mode="before")
    @classmethod
    def _preset_defaults(cls, data: Any) -> Any:
        if isinstance(data, dict) and data.get("preset", "clean") in WORLD_PRESETS:
            return {**WORLD_PRESETS[data.get("preset", "clean")], **data}
        return data

    def with_preset(self, preset: str) -> WorldConfig:
        """This section in another preset: that preset's defaults, with every key this one
        changed from its own preset's kept."""
        own = WorldConfig(preset=self.preset).model_dump()
        changed = {k: v for k, v in self.model_dump().items() if own[k] != v}
        return WorldConfig.model_validate({**changed, "preset": preset})

    @field_validator("people_speed", "light_level", "camera_exposure")
    @classmethod
    def _ordered(cls, pair: list[float], info) -> list[float]:
        lo, hi = _PAIR_LIMITS[info.field_name]
        if not all(lo <= v <= hi for v in pair) or pair[0] > pair[1]:
            raise ValueError(f"expected [min, max] with {lo} <= min <= max <= {hi}")
        return pair


class Config(_Section):
    """One typed config chooses the back ends and sets the tree, the grounder and the
    simulator. Give a YAML file with `--config FILE` (every key optional) and override single
    values with `--set section.key=value` (the value is read as YAML, e.g.
    `--set grounder.hidden=[room4]`; `1e-3` is read as a number). Unknown keys and bad values
    are errors that name the key. Types are strict: `"10"` or `true` is not a number. Every
    number has a range that keeps a run finite in time and memory (the tables' last column).

        grounder: {miss_rate: 0.2}
        tree: {variant: coarse_only, replans: 1}
        sim: {width: 640, height: 480}
    """

    grounder: GrounderConfig = GrounderConfig()
    coarse: CoarseConfig = CoarseConfig()
    refiner: RefinerConfig = RefinerConfig()
    planner: PlannerConfig = PlannerConfig()
    tree: TreeConfig = TreeConfig()
    vlm: VlmConfig = VlmConfig()
    sim: SimConfig = SimConfig()
    world: WorldConfig = WorldConfig()


def _set_dotted(data: dict, key: str, value: Any, label: str = "--set") -> None:
    parts = key.split(".")
    if len(parts) > 4 or len(key) > 200 or not all(parts):
        raise ConfigError(f"{label} {_short(key)}: expected section.key")
    d = data
    for p in parts[:-1]:
        d = d.setdefault(p, {})
        if not isinstance(d, dict):
            raise ConfigError(f"{label} {_short(key)}: {_short(p)!r} is not a section")
    d[parts[-1]] = value


def load_config(
    path: str | Path | None = None, overrides: list[str] | tuple = (), label: str = "--set"
) -> Config:
    """The configuration from ``path`` (optional) with ``key=value`` overrides applied.

    ``label`` names where overrides come from in errors (``--set``, a ROS parameter)."""
    data: Any = {}
    source = str(path) if path else "<defaults>"
    if path:
        try:
            data = load_yaml(path, "config")
        except InputFileError as err:
            raise ConfigError(str(err)) from None
        if data is None:
            data = {}
        if not isinstance(data, dict):
            raise ConfigError(f"{path}: expected a mapping of sections")
    set_keys: set[str] = set()
    for item in overrides:
        key, sep, raw = str(item).partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"{label} {_short(item)}: expected section.key=value")
        try:
            value = parse_yaml_value(raw, f"{label} {_short(item)}")
        except PmNavError as err:
            raise ConfigError(str(err)) from None
        if isinstance(value, str) and _NUMBER.fullmatch(value.strip()):
            value = float(value)  # YAML 1.1 reads 1e3 as text; on the command line it is a number
        _set_dotted(data, key.strip(), value, label)
        set_keys.add(key.strip())
    return config_from_data(data, source, {k: label for k in set_keys})


def config_from_data(data: Any, source: str, sources: dict[str, str] | None = None) -> Config:
    """``data`` validated as a Config; else a ConfigError of one line naming ``source`` (or,
    for a key in ``sources``, where that key was set), the key and what is wrong."""
    try:
        return Config.model_validate(data)
    except ValidationError as err:
        e = err.errors()[0]
        where = ".".join(str(p) for p in e["loc"])
        source = (sources or {}).get(where, source)
        more = f" (and {len(err.errors()) - 1} more)" if len(err.errors()) > 1 else ""
        msg = e["msg"].removeprefix("Value error, ")
        got = e.get("input")
        shown = "" if isinstance(got, (dict, list)) else f" (got {_short(repr(got))})"
        raise ConfigError(f"{source}: {where}: {msg}{shown}{more}") from None


_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+")


def _short(text: str, n: int = 60) -> str:
    return text if len(text) <= n else text[: n - 3] + "..."
