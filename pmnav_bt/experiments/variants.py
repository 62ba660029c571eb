"""Named evaluation variants: a tree variant plus config overrides and a label. A variant
whose grounder is an oracle (its registry spec says ``oracle=True``: ground-truth
perception) is labelled so in every table. The tree variant
(``tree.variant``) must be one registered in ``pmnav_bt/tree_variants.py``: a row naming another
is refused when its config is made.

Adding a variant is one line in ``VARIANTS``, e.g.
``Variant("mapless", "map-less", (("tree.variant", "mapless"),), tables=("1",))``.
A variant's overrides are applied on top of the run's config (``--config``/``--set``),
so anything it does not set (the grounder, for ``pmnav``) is the run's; the report
states each variant's grounder from its own config.

A variant runs in the world the run's config describes (its ``world`` section), or in a
named world preset: ``pmnav@realistic`` is ``pmnav`` with ``world.preset=realistic`` (keys
of the world section the run's config changed from its own preset carry over), and
``--worlds clean,realistic`` (the evaluation's default) runs every listed variant in each
preset, side by side. Results stored under a plain variant name (before worlds were
named) still load and show.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from dataclasses import dataclass

from pmnav_bt.config import WORLD_PRESETS, Config, _set_dotted, config_from_data
from pmnav_bt.errors import PmNavError
from pmnav_bt.registry import GROUNDERS

ORACLE_LABEL = "oracle: simulator labels"


@dataclass(frozen=True)
class Variant:
    """One row of the evaluation: ``overrides`` are ``section.key: value`` pairs;
    ``tables``: the report's tables it appears in ("1": navigation vs the baselines,
    "4": action refinement)."""

    name: str
    label: str
    overrides: tuple[tuple[str, object], ...]
    tables: tuple[str, ...] = ("1", "4")

    @property
    def oracle(self) -> bool:
        """Whether the grounder this variant sets declares itself an oracle (a variant that
        sets none runs the run's grounder, which its report row states)."""
        backend = dict(self.overrides).get("grounder.backend")
        return backend is not None and GROUNDERS.spec(str(backend)).oracle

    @property
    def title(self) -> str:
        """The label as shown in tables: oracles say so."""
        return f"{self.label} ({ORACLE_LABEL})" if self.oracle else self.label

    def config(self, base: Config) -> Config:
        """``base`` with this variant's overrides applied (a ConfigError of one line when
        they make no valid config, e.g. an unregistered tree variant)."""
        data = base.model_dump(mode="json")
        for key, value in self.overrides:
            if key == "world.preset":  # a new preset's defaults, the run's own changes kept
                data["world"] = base.world.with_preset(str(value)).model_dump(mode="json")
                continue
            _set_dotted(data, key, value, label=f"variant {self.name}")
        return config_from_data(data, f"variant {self.name}")

    def in_world(self, preset: str) -> Variant:
        """This variant in the world preset ``preset`` (named ``<name>@<preset>``)."""
        return Variant(
            f"{self.name}@{preset}",
            f"{self.label}, {preset} world",
            (*self.overrides, ("world.preset", preset)),
            self.tables,
        )


VARIANTS: dict[str, Variant] = {
    v.name: v
    for v in (
        Variant("pmnav", "PM-Nav", (("tree.variant", "pmnav"),)),
        Variant("coarse_only", "coarse-only", (("tree.variant", "coarse_only"),)),
        Variant(
            "pmnav_pixelnav",
            "PM-Nav, fine: PixelNav",
            (("tree.variant", "pmnav"), ("refiner.backend", "pixelnav")),
            tables=("4",),
        ),
        Variant(
            "pmnav_oracle",
            "PM-Nav",
            (("tree.variant", "pmnav"), ("grounder.backend", "sim_gt")),
            tables=("4",),
        ),
        # the paper's SG-Nav/InstructNav rows: no priori-map, no plan (docs/baseline.md)
        Variant("mapless", "map-less baseline", (("tree.variant", "mapless"),), tables=("1",)),
    )
}


def get_variant(name: str) -> Variant:
    """The variant called ``name`` (``VARIANT`` or ``VARIANT@WORLD``); PmNavError naming the
    known ones otherwise."""
    base, sep, world = name.partition("@")
    if base not in VARIANTS:
        raise PmNavError(f"unknown variant {base!r}; choose from {', '.join(VARIANTS)}")
    if not sep:
        return VARIANTS[base]
    if world not in WORLD_PRESETS:
        raise PmNavError(
            f"variant {name!r}: unknown world {world!r}; choose from {', '.join(WORLD_PRESETS)}"
        )
    return VARIANTS[base].in_world(world)


def find_variant(name: str) -> Variant | None:
    """The variant called ``name``, or None when it is not (or no longer) registered."""
    try:
        return get_variant(name)
    except PmNavError:
        return None


def variant_title(name: str) -> str:
    """A variant's table title, or its name when it is not (or no longer) registered."""
    v = find_variant(name)
    return v.title if v else name


def in_worlds(names: Iterable[str], worlds: Iterable[str]) -> list[str]:
    """Every variant of ``names`` in each world preset of ``worlds`` ("pmnav", "realistic"
    -> "pmnav@realistic"), grouped by world; a name that already says its world is kept
    once. PmNavError for an unknown preset or no preset at all."""
    worlds = list(worlds)
    if not worlds:
        raise PmNavError(f"name at least one world; choose from {', '.join(WORLD_PRESETS)}")
    for w in worlds:
        if w not in WORLD_PRESETS:
            raise PmNavError(f"unknown world {w!r}; choose from {', '.join(WORLD_PRESETS)}")
    out = [f"{n}@{w}" for w in worlds for n in names if "@" not in n]
    return out + [n for n in names if "@" in n and n not in out]


def variant_configs(base: Config, names: Iterable[str]) -> dict[str, Config]:
    """One config per named variant, in the order given."""
    return {n: get_variant(n).config(base) for n in names}


def config_hash(config: Config) -> str:
    """A short, stable hash of everything in a config (keys sorted)."""
    text = json.dumps(config.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
