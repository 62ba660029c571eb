"""Back ends by name: one registry per seam.

Each seam (grounder, coarse direction, refiner, planner) has a registry of named back
ends. An entry points at its factory as ``"module:function"`` and is imported only when
chosen, so heavy back ends (OCR models, torch networks, an HTTP client) cost nothing
unless configured. A factory takes the ``backends.BackendDeps`` and returns the back end;
``backends.build_backends`` builds a run's back ends from the config, for the simulator
and the robot alike. The config checks its ``backend`` names here, so this module knows
nothing of the config.

    >>> GROUNDERS.names()
    ['sim_gt', ...]

New back ends: ``GROUNDERS.register(GrounderSpec("mine", "my_pkg.grounder:build", ...,
reading="my_pkg.grounder:MY_READING"))`` and ``--set grounder.backend=mine``. A grounder's
spec also declares how far and how often it names signs (its *reading model*, which the
tree's search ranges and the localization belief's recall follow:
``perception/read_range.py``) and whether it is an oracle (results label it so).
"""

from __future__ import annotations

import difflib
import importlib
from dataclasses import dataclass
from typing import Any, Protocol

from pmnav_bt.errors import BackendError, ConfigError


@dataclass(frozen=True)
class BackendSpec:
    """A named back end: where its factory is, whether it needs simulator labels, a summary."""

    name: str
    factory: str  # "package.module:function", imported when the back end is built
    summary: str
    needs_sim_labels: bool = False

    @property
    def tags(self) -> list[str]:
        """What ``pmnav backends`` says of it besides its summary."""
        return ["sim only"] if self.needs_sim_labels else []


# A grounder's reading model when it reads every sign in sight up to ``grounder.max_range``
# (the simulator's labels), with misses at the belief's constant rate: no measured tables.
ORACLE_READING = "oracle"


@dataclass(frozen=True)
class GrounderSpec(BackendSpec):
    """A named grounder. ``reading``: its reading model, ``"package.module:NAME"`` of a
    ``perception.read_range.ReadingModel`` (its measured range and recall by distance),
    imported when asked for, or ``ORACLE_READING``; None: it declares none, and asking for
    its search ranges is an error (never another reader's tables). ``oracle``: its figures
    are an upper bound, not perception (results label it ``(oracle)``)."""

    reading: str | None = None
    oracle: bool = False

    @property
    def tags(self) -> list[str]:
        return super().tags + (["oracle"] if self.oracle else [])


class FactoryDeps(Protocol):
    """What a registry reads of a factory's inputs (``backends.BackendDeps``) before it
    builds: whether the run is on a robot."""

    on_robot: bool


class Named:
    """Specs by name, each with a ``name``, declared with one spec class (``kind``): what a
    config key (``key``, e.g. ``grounder.backend``, ``tree.variant``) may name. An unknown
    name is one ConfigError that lists the registered ones."""

    def __init__(self, key: str, what: str, specs: list, kind: type):
        self.key = key
        self.what = what  # "back end", "tree variant": for messages
        self.kind = kind
        self._specs: dict[str, Any] = {}
        for spec in specs:
            self.register(spec)

    def register(self, spec) -> None:
        if not isinstance(spec, self.kind):
            raise TypeError(f"a {self.key} {self.what} is declared with a {self.kind.__name__}")
        if spec.name in self._specs and self._specs[spec.name] != spec:
            raise ValueError(f"{self.key} {self.what} {spec.name!r} is registered already")
        self._specs[spec.name] = spec

    def names(self) -> list[str]:
        return list(self._specs)

    def spec(self, name: str) -> Any:
        """The entry for ``name``; an unknown name lists the registered ones."""
        try:
            return self._specs[name]
        except KeyError:
            close = difflib.get_close_matches(name, self._specs, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ConfigError(
                f"{self.key}: unknown {self.what} {name!r}{hint}; "
                f"registered: {', '.join(self._specs)}"
            ) from None


class Registry(Named):
    """The named back ends of one seam (``kind``: the spec class they declare themselves
    with, e.g. ``GrounderSpec``)."""

    def __init__(self, seam: str, specs: list[BackendSpec], kind: type = BackendSpec):
        self.seam = seam
        super().__init__(f"{seam}.backend", "back end", specs, kind)

    def build(self, name: str, deps: FactoryDeps) -> Any:
        """Build the back end ``name`` (refusing simulator-only back ends on a robot)."""
        spec = self.spec(name)
        if spec.needs_sim_labels and deps.on_robot:
            others = [s.name for s in self._specs.values() if not s.needs_sim_labels]
            raise BackendError(
                f"{self.seam}.backend {name!r} reads the simulator's segmentation labels and "
                f"cannot run on a robot; choose one of: {', '.join(others) or '(none)'}"
            )
        return load(spec.factory)(deps)


def load(target: str) -> Any:
    """The object ``"package.module:NAME"`` names (a factory, a reading model), imported now."""
    module, _, attr = target.partition(":")
    return getattr(importlib.import_module(module), attr)


# measured by benchmarks/bench_signs.py and sign_ranges.py
PP_OCR_READING = "pmnav_bt.perception.read_range:PP_OCR"

GROUNDERS = Registry(
    "grounder",
    [
        GrounderSpec(
            "sim_gt",
            "pmnav_bt.perception.grounders.ground_truth:build",
            "the simulator's segmentation (oracle; misses/noise configurable)",
            needs_sim_labels=True,
            reading=ORACLE_READING,
            oracle=True,
        ),
        GrounderSpec(
            "ocr",
            "pmnav_bt.perception.grounders.ocr:build",
            "reads door and landmark signs (PP-OCR); floor and walls from depth",
            reading=PP_OCR_READING,
        ),
        GrounderSpec(
            "gdino_sam",
            "pmnav_bt.perception.grounders.gdino_sam:build",
            "GroundingDINO + SAM (transformers, local weights); signs by OCR; depth surfaces",
            reading=PP_OCR_READING,  # its signs are read by the same PP-OCR reader
        ),
    ],
    kind=GrounderSpec,
)


def grounder_label(name: str) -> str:
    """The grounder's name as results print it: ``sim_gt (oracle)`` for a back end declared
    an oracle, so an oracle's figures are never taken for perception."""
    return f"{name} (oracle)" if GROUNDERS.spec(name).oracle else name


COARSE = Registry(
    "coarse",
    [
        BackendSpec(
            "detector",
            "pmnav_bt.perception.coarse:build_detector",
            "ground the target in every view, take the best score",
        ),
        BackendSpec(
            "vlm",
            "pmnav_bt.vlm.coarse:build",
            "a VLM picks the view from the stitched panorama (OpenAI-compatible server)",
        ),
    ],
)
REFINERS = Registry(
    "refiner",
    [
        BackendSpec(
            "geometric",
            "pmnav_bt.perception.refiners.geometric:build",
            "goal pixel -> bearing from the intrinsics, range from depth",
        ),
        BackendSpec(
            "pixelnav",
            "pmnav_bt.pixelnav.policy:build",
            "PixelNav policy (torch, shipped weights) drives the approach to the goal pixel",
        ),
    ],
)
PLANNERS = Registry(
    "planner",
    [
        BackendSpec(
            "graph",
            "pmnav_bt.planning.graph_planner:build",
            "shortest path on the priori-map graph",
        ),
        BackendSpec(
            "vlm",
            "pmnav_bt.vlm.planner:build",
            "a VLM plans with the H-CoT prompt; checked against the map, graph fallback",
        ),
    ],
)
REGISTRIES = {r.seam: r for r in (GROUNDERS, COARSE, REFINERS, PLANNERS)}
