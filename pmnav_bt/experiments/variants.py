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
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from dataclasses import dataclass

from pmnav_bt.config import Config, _set_dotted, config_from_data
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
            _set_dotted(data, key, value, label=f"variant {self.name}")
        return config_from_data(data, f"variant {self.name}")


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
    """The variant called ``name``; PmNavError naming the known ones otherwise."""
    if name not in VARIANTS:
        raise PmNavError(f"unknown variant {name!r}; choose from {', '.join(VARIANTS)}")
    return VARIANTS[name]


def variant_title(name: str) -> str:
    """A variant's table title, or its name when it is not (or no longer) registered."""
    v = VARIANTS.get(name)
    return v.title if v else name


def variant_configs(base: Config, names: Iterable[str]) -> dict[str, Config]:
    """One config per named variant, in the order given."""
    return {n: get_variant(n).config(base) for n in names}


def config_hash(config: Config) -> str:
    """A short, stable hash of everything in a config (keys sorted)."""
    text = json.dumps(config.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
