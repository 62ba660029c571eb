"""What the evaluation commands read from their options: ``pmnav sim eval``, ``pmnav sim
table3``, ``pmnav report``, ``pmnav plan eval`` and the benchmarks that run episodes.

Each turns one option's text into what the run needs (building names, tiers, the config,
the number of jobs, Table 3's read ranges) or stops with a ``PmNavError`` that names the
option. Imports are inside the functions, so that ``pmnav --help`` stays quick.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pmnav_bt import cli_values
from pmnav_bt.errors import PmNavError

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import Config


def name_list(text: str, option: str) -> list[str]:
    """A comma-separated option (``--variants a,b``) as its names; a list that names
    nothing (``,`` or spaces) is refused: it would run nothing and write an empty table."""
    names = [part.strip() for part in text.split(",") if part.strip()]
    if not names:
        raise PmNavError(f"{option} {text!r}: names nothing; give one or more, comma-separated")
    return names


def tier_names(tier: str) -> list[str]:
    """``--tier``: easy, medium, hard, a comma-separated list of them, or all."""
    from pmnav_bt.eval.tiers import parse_tiers

    try:
        return parse_tiers(tier)
    except ValueError as err:
        raise PmNavError(f"--tier: {err}") from None


def building_names(building: str, option: str = "--building") -> list[str]:
    """``--building``: comma-separated files, built-in names, 'all' (every built-in),
    FAMILY:N and FAMILY_heldout:N (``catalogue.family_members``)."""
    from pmnav_bt.map.catalogue import builtin_buildings, family_members

    out: list[str] = []
    for part in name_list(building, option):
        try:
            members = family_members(part)
        except ValueError as err:
            raise PmNavError(f"{option} {err}") from None
        out += builtin_buildings() if part == "all" else members or [part]
    return out


def variant_names(variants: str, worlds: str) -> list[str]:
    """``--variants`` (comma-separated, at least one) run in each world preset of
    ``--worlds`` (comma-separated, at least one), as ``VARIANT@WORLD`` names."""
    from pmnav_bt.experiments.variants import get_variant, in_worlds

    names, presets = name_list(variants, "--variants"), name_list(worlds, "--worlds")
    try:
        out = in_worlds(names, presets)
        for name in out:
            get_variant(name)
    except PmNavError as err:
        raise PmNavError(f"--worlds/--variants: {err}") from None
    return out


def table3_building_names(
    building: str, family_size: int, option: str = "--building"
) -> list[str]:
    """Table 3's ``--building``: as ``building_names``, where the bare family name
    ``sign_sparse`` stands for its first ``--family-size`` members."""
    from pmnav_bt.map.generate import SIGN_SPARSE_FAMILY

    names: list[str] = []
    for part in name_list(building, option):
        if part == SIGN_SPARSE_FAMILY:
            names += [f"{SIGN_SPARSE_FAMILY}_{k}" for k in range(family_size)]
        else:
            names += building_names(part, option)
    return names


def run_config(config: Path | None, overrides: list[str] | None) -> Config:
    """``--config FILE`` with the ``--set section.key=value`` overrides applied."""
    from pmnav_bt.config import load_config

    return load_config(config, overrides or [])


def job_count(jobs: int | None) -> int:
    """``--jobs``: as given (checked), or 2, at most the CPUs."""
    return cli_values.jobs(jobs) if jobs is not None else min(2, cli_values.cpu_count())


def class_ranges(class_range: str, cfg: Config) -> dict[str, float] | None:
    """``--class-range``: the read range per plate kind Table 3's classes count landmarks
    within (``stack``: the grounder's; ``map``: None, the map's ``READ_RANGE_M``)."""
    from pmnav_bt.perception.read_range import landmark_ranges

    if class_range not in ("stack", "map"):
        raise PmNavError(f"--class-range must be 'stack' or 'map', not {class_range!r}")
    return landmark_ranges(cfg) if class_range == "stack" else None


def ranges_text(ranges: dict[str, float] | None) -> str:
    """Table 3's read ranges (``class_ranges``) as its header prints them."""
    from pmnav_bt.pose.visibility import READ_RANGE_M

    if ranges is None:
        return f"<= {READ_RANGE_M:g} m"
    return "the grounder's reliable read range: " + ", ".join(
        f"{k} plates <= {r:g} m" for k, r in ranges.items()
    )
