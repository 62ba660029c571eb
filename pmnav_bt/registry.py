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

New back ends: ``GROUNDERS.register(BackendSpec("mine", "my_pkg.grounder:build", ...))``
and ``--set grounder.backend=mine``.
"""

from __future__ import annotations

import difflib
import importlib
from collections.abc import Callable
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


class FactoryDeps(Protocol):
    """What a registry reads of a factory's inputs (``backends.BackendDeps``) before it
    builds: whether the run is on a robot."""

    on_robot: bool


class Registry:
    """The named back ends of one seam."""

    def __init__(self, seam: str, specs: list[BackendSpec]):
        self.seam = seam
        self._specs: dict[str, BackendSpec] = {}
        for spec in specs:
            self.register(spec)

    def register(self, spec: BackendSpec) -> None:
        if spec.name in self._specs and self._specs[spec.name] != spec:
            raise ValueError(f"{self.seam} back end {spec.name!r} is registered already")
        self._specs[spec.name] = spec

    def names(self) -> list[str]:
        return list(self._specs)

    def spec(self, name: str) -> BackendSpec:
        """The entry for ``name``; an unknown name lists the registered ones."""
        try:
            return self._specs[name]
        except KeyError:
            close = difflib.get_close_matches(name, self._specs, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ConfigError(
                f"{self.seam}.backend: unknown back end {name!r}{hint}; "
                f"registered: {', '.join(self._specs)}"
            ) from None

    def build(self, name: str, deps: FactoryDeps) -> Any:
        """Build the back end ``name`` (refusing simulator-only back ends on a robot)."""
        spec = self.spec(name)
        if spec.needs_sim_labels and deps.on_robot:
            others = [s.name for s in self._specs.values() if not s.needs_sim_labels]
            raise BackendError(
                f"{self.seam}.backend {name!r} reads the simulator's segmentation labels and "
                f"cannot run on a robot; choose one of: {', '.join(others) or '(none)'}"
            )
        return _load(spec.factory)(deps)


def _load(target: str) -> Callable[[FactoryDeps], Any]:
    module, _, attr = target.partition(":")
    return getattr(importlib.import_module(module), attr)


GROUNDERS = Registry(
    "grounder",
    [
        BackendSpec(
            "sim_gt",
            "pmnav_bt.perception.grounders.ground_truth:build",
            "the simulator's segmentation (oracle; misses/noise configurable)",
            needs_sim_labels=True,
        ),
        BackendSpec(
            "ocr",
            "pmnav_bt.perception.grounders.ocr:build",
            "reads door and landmark signs (PP-OCR); floor and walls from depth",
        ),
        BackendSpec(
            "gdino_sam",
            "pmnav_bt.perception.grounders.gdino_sam:build",
            "GroundingDINO + SAM (transformers, local weights); signs by OCR; depth surfaces",
        ),
    ],
)


def grounder_label(name: str) -> str:
    """The grounder's name as results print it: ``sim_gt (oracle)`` for a back end that
    reads the simulator's labels, so an oracle's figures are never taken for perception."""
    return f"{name} (oracle)" if GROUNDERS.spec(name).needs_sim_labels else name


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
