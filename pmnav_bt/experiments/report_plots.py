"""The report's charts (matplotlib, headless Agg): SR and SPL per tier per variant, and
failure codes per variant."""

from __future__ import annotations

import math
from pathlib import Path

from pmnav_bt.experiments.report_tables import (
    Results,
    failure_counts,
    tier_stats,
    tiers_present,
)
from pmnav_bt.experiments.variants import variant_title
from pmnav_bt.render import headless_pyplot


def plot_sr_spl(results: Results, path: Path) -> Path:
    """Two panels (SR, SPL), bars grouped by tier, one colour per variant, n under each
    tier."""
    plt = headless_pyplot()
    tiers = [*tiers_present(results), "all"]
    names = list(results)
    stats = {n: tier_stats(results[n]) for n in names}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    width = 0.8 / max(1, len(names))
    for ax, metric, k in ((axes[0], "SR", 0), (axes[1], "SPL", 1)):
        for j, n in enumerate(names):
            xs = [i + (j - (len(names) - 1) / 2) * width for i in range(len(tiers))]
            ys = [stats[n][t][k] if t in stats[n] else 0.0 for t in tiers]
            bars = ax.bar(xs, ys, width, label=variant_title(n))
            for b, y in zip(bars, ys, strict=True):
                ax.annotate(
                    f"{y:.0f}",
                    (b.get_x() + b.get_width() / 2, y),
                    ha="center",
                    va="bottom",
                    fontsize=7,
                )
        counts = [max((stats[n][t][2] for n in names if t in stats[n]), default=0) for t in tiers]
        ax.set_xticks(
            range(len(tiers)), [f"{t}\n(n={c})" for t, c in zip(tiers, counts, strict=True)]
        )
        ax.set_title(f"{metric} per tier (%)")
        ax.set_ylim(0, 110)
        ax.grid(axis="y", alpha=0.3)
    axes[0].set_ylabel("%")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(4, len(names)), fontsize=8)
    rows = math.ceil(len(names) / 4)
    fig.tight_layout(rect=(0, 0.06 * rows, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_failures(results: Results, path: Path) -> Path:
    """Stacked bars: failed runs per variant, by failure code."""
    plt = headless_pyplot()
    counts = failure_counts(results)
    names = list(results)
    codes = sorted({c for cnt in counts.values() for c in cnt})
    fig, ax = plt.subplots(figsize=(8, 0.6 * len(names) + 1.8))
    left = [0] * len(names)
    for c in codes:
        vals = [counts[n][c] for n in names]
        ax.barh([variant_title(n) for n in names], vals, left=left, label=c)
        left = [a + b for a, b in zip(left, vals, strict=True)]
    for i, n in enumerate(names):
        ax.annotate(
            f" {left[i]} of {len(results[n])} failed", (left[i], i), va="center", fontsize=8
        )
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("failed runs")
    ax.set_title("Failure codes per variant")
    ax.set_xlim(0, max(left + [1]) * 1.35)
    if codes:
        ax.legend(fontsize=8, loc="lower right")
    ax.invert_yaxis()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
