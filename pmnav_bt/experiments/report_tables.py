"""The report's tables: Table 1 (navigation per tier) and Table 4 (action refinement)
beside the paper's numbers, the variants and the failure codes. Pure functions of the
results; Table 3 is ``localization_study.table``."""

from __future__ import annotations

import math
import re
from collections import Counter

from pmnav_bt.config import Config
from pmnav_bt.eval.metrics import EpisodeResult, aggregate_by_tier, contact_totals
from pmnav_bt.eval.tiers import CROSS_LEVEL, TIER_NAMES
from pmnav_bt.experiments.variants import find_variant, variant_title

# The paper's Table 1 (simulation): method -> tier -> (SR %, SPL %).
PAPER_TABLE1 = {
    "SG-Nav": {"easy": (12, 4.96), "medium": (4, 1.92), "hard": (0, 0.0)},
    "InstructNav": {"easy": (18, 5.81), "medium": (8, 2.80), "hard": (0, 0.0)},
    "PM-Nav": {"easy": (88, 77.40), "medium": (68, 58.60), "hard": (46, 36.40)},
}
# The paper's Table 4: action level -> tier -> (SR %, SPL %).
PAPER_TABLE4 = {
    "coarse": {"easy": (32, 22.61), "medium": (10, 7.71), "hard": (0, 0.0)},
    "fine": PAPER_TABLE1["PM-Nav"],
}

Results = dict[str, list[EpisodeResult]]


def _cell(sr: float | None, spl: float | None) -> str:
    if sr is None or spl is None or math.isnan(sr):
        return "- | -"
    return f"{sr:.1f} | {spl:.1f}"


def tier_stats(rs: list[EpisodeResult]) -> dict[str, tuple[float, float, int]]:
    """tier -> (SR %, SPL %, runs) over the episodes that ran (errors left out)."""
    table = aggregate_by_tier(rs, overall=True)
    return {r.tier: (r.sr, r.spl, r.episodes) for r in table.rows}


def tiers_present(results: Results) -> list[str]:
    seen = {r.tier for rs in results.values() for r in rs}
    return [t for t in TIER_NAMES if t in seen] + sorted(seen - set(TIER_NAMES))


def table1(results: Results) -> str:
    """SR/SPL per tier for the variants of Table 1 that ran, then the paper's rows."""
    tiers = [t for t in TIER_NAMES if t in tiers_present(results)]
    if not tiers:
        return f"(no {', '.join(TIER_NAMES)} episodes in these results)"
    head = "| method | " + " | ".join(f"{t} SR | {t} SPL" for t in tiers) + " | runs |"
    lines = [head, "|---|" + "---|---|" * len(tiers) + "---|"]
    for name, rs in results.items():
        v = find_variant(name)
        if v is not None and "1" not in v.tables:
            continue
        st = tier_stats(rs)
        cells = [_cell(*st[t][:2]) if t in st else "- | -" for t in tiers]
        lines.append(f"| {variant_title(name)} | " + " | ".join(cells) + f" | {len(rs)} |")
    for method, row in PAPER_TABLE1.items():
        cells = [_cell(*row[t]) if t in row else "- | -" for t in tiers]
        lines.append(f"| *paper: {method}* | " + " | ".join(cells) + " | |")
    return "\n".join(lines)


def table4(results: Results) -> str:
    """Rows per tier: the coarse-only and fine variants that ran (and the oracle), SR/SPL,
    beside the paper's coarse and fine columns."""
    cols = [n for n in results if (v := find_variant(n)) is not None and "4" in v.tables]
    if not cols:
        return "(no Table 4 variant in these results)"
    tiers = [t for t in TIER_NAMES if t in tiers_present(results)]
    stats = {n: tier_stats(results[n]) for n in cols}
    head = (
        "| tier | "
        + " | ".join(f"{variant_title(n)} SR | {variant_title(n)} SPL" for n in cols)
        + " | paper coarse SR | paper coarse SPL | paper fine SR | paper fine SPL |"
    )
    lines = [head, "|---|" + "---|---|" * (len(cols) + 2)]
    for t in [*tiers, "all"]:
        cells = [_cell(*stats[n][t][:2]) if t in stats[n] else "- | -" for n in cols]
        paper = [
            _cell(*PAPER_TABLE4[k][t]) if t in PAPER_TABLE4[k] else "- | -"
            for k in ("coarse", "fine")
        ]
        lines.append(f"| {t} | " + " | ".join(cells + paper) + " |")
    return "\n".join(lines)


def variants_table(results: Results, configs: dict[str, Config]) -> str:
    """What each variant is: tree, grounder, coarse and refiner back ends, world preset,
    oracle or not."""
    lines = [
        "| variant | shown as | tree | grounder | coarse | refiner | world | oracle | runs "
        "| errors |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, rs in results.items():
        c = configs.get(name)
        v = find_variant(name)
        what = (
            [c.tree.variant, c.grounder.backend, c.coarse.backend, c.refiner.backend]
            + [c.world.preset]
            if c
            else ["?"] * 5
        )
        errors = sum(r.error is not None for r in rs)
        lines.append(
            f"| {name} | {variant_title(name)} | {' | '.join(what)} | "
            f"{'yes' if v and v.oracle else 'no'} | {len(rs)} | {errors} |"
        )
    return "\n".join(lines)


def failure_code(r: EpisodeResult) -> str | None:
    """A result's failure as a short code: the failure code the tree reported, "ERROR"
    for a run that crashed, "OTHER" for a reason without a code, None for a success."""
    if r.error is not None:
        return "ERROR"
    if r.success:
        return None
    m = re.match(r"[A-Z][A-Z_]+", r.failure_reason or "")
    return m.group(0) if m else "OTHER"


def failure_counts(results: Results) -> dict[str, Counter]:
    return {
        n: Counter(c for r in rs if (c := failure_code(r)) is not None) for n, rs in results.items()
    }


def failures_table(results: Results) -> str:
    counts = failure_counts(results)
    codes = sorted({c for cnt in counts.values() for c in cnt})
    if not codes:
        return "(no failures)"
    lines = [
        "| variant | " + " | ".join(codes) + " |",
        "|---|" + "---|" * len(codes),
    ]
    for n, cnt in counts.items():
        lines.append(f"| {variant_title(n)} | " + " | ".join(str(cnt[c]) for c in codes) + " |")
    return "\n".join(lines)


def cross_level_table(results: Results) -> str | None:
    """The episodes across levels (tier cross_level), a row per variant: runs, SR and SPL
    (%, over the runs that ran), the lift rides on their routes, the calls the lift
    answered full ("lift full met") and the failure codes with their counts; None when no
    result is of that tier."""
    rows = {n: [r for r in rs if r.tier == CROSS_LEVEL] for n, rs in results.items()}
    rows = {n: rs for n, rs in rows.items() if rs}
    if not rows:
        return None
    lines = [
        "| variant | runs | SR | SPL | rides | lift full met | failures |",
        "|---|---|---|---|---|---|---|",
    ]
    for n, rs in rows.items():
        ran = [r for r in rs if r.error is None]
        sr, spl = tier_stats(rs).get(CROSS_LEVEL, (math.nan, math.nan, 0))[:2]
        rides = sum(r.rides or 0 for r in ran)
        full = sum(r.lifts_full or 0 for r in ran)
        codes = Counter(c for r in rs if (c := failure_code(r)) is not None)
        fails = ", ".join(f"{c} {k}" for c, k in sorted(codes.items())) or "none"
        lines.append(
            f"| {variant_title(n)} | {len(rs)} | {_cell(sr, spl)} | {rides} | {full} | {fails} |"
        )
    return "\n".join(lines)


def contacts_table(results: Results) -> str:
    """Per variant over the episodes that ran: the robot's collisions with anything (total
    and per 100 episodes, the target's unit) and its contacts with people."""
    lines = [
        "| variant | episodes | collisions | collisions per 100 episodes | people contacts |",
        "|---|---|---|---|---|",
    ]
    for n, rs in results.items():
        c = contact_totals(rs)
        lines.append(
            f"| {variant_title(n)} | {c.episodes} | {c.collisions} | {c.per_100_text()} | "
            f"{c.people_text()} |"
        )
    return "\n".join(lines)


def per_building_table(results: Results) -> str:
    """SR per building per variant (all tiers): where a variant fails."""
    names = list(results)
    buildings = sorted({r.building for rs in results.values() for r in rs})
    lines = [
        "| building | " + " | ".join(f"{variant_title(n)} SR (n)" for n in names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for b in buildings:
        cells = []
        for n in names:
            rs = [r for r in results[n] if r.building == b and r.error is None]
            cells.append(
                f"{100 * sum(r.success for r in rs) / len(rs):.0f} ({len(rs)})" if rs else "-"
            )
        lines.append(f"| {b} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
